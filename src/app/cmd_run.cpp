// spidar-mr run: the live mixed-reality session from one YAML file (live_config.hpp), headless or
// in a window with the GUI (live_gui.hpp), optionally recorded (session_recorder.hpp).
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <thread>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "spidar/session/recording_writer.hpp"
#include "commands.hpp"
#include "live_exit.hpp"
#include "live_gui.hpp"
#include "spidar/session/live_session.hpp"
#include "signal_scope.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/config.hpp"

namespace spidar::app {
namespace {

nlohmann::json summary_json(const session::LiveSession& s, const std::string& ended_by, double wall_s) {
  nlohmann::json j;
  j["ended_by"] = ended_by;
  j["seconds"] = wall_s;
  j["frames"] = s.frames();
  j["camera_frames"] = s.camera_frames();
  const auto st = s.servo().stats();
  j["servo"] = {{"rate_hz", st.rate_hz},         {"cycles", st.cycles},
                {"jitter_p99_us", st.jitter_p99_us}, {"overruns", st.overruns},
                {"faults", device::fault_names(st.faults)},
                {"realtime_scheduling", st.realtime_scheduling}, {"idle_spin", st.idle_spin}};
  j["registration"] = {{"iou_vs_silhouette_mean", s.view().iou_mean()},
                       {"ms_mean", s.view().registration_ms_mean()}};
  if (auto c = s.cube_status())
    j["cube"] = {{"turns", c->turns}, {"solved", c->solved}, {"lift_mm", c->lift * 1e3}};
  if (const session::SessionRecorder* r = s.recorder()) {
    j["recording"] = {{"dir", r->dir()},
                      {"device_cycles", r->device_records()},
                      {"fingertip_samples", r->fingertip_records()},
                      {"frames", r->frames()},
                      {"lost", r->lost()}};
    if (!r->error().empty()) j["recording"]["error"] = r->error();
  }
  if (const std::string e = s.error(); !e.empty()) j["error"] = e;
  return j;
}

}  // namespace

Action add_run(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run", "The live mixed-reality session (device, camera, physics, registration, compositing) "
             "from one YAML file; simulated hardware in configs/lab-example.yaml");
  struct Args {
    std::string config;
    double seconds = 0;
    bool headless = false;
    std::string record;
    std::string record_frames = "video";
    std::string screenshot;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--config", a->config, "live session YAML (see configs/lab-example.yaml)")->required();
  cmd->add_option("--seconds", a->seconds, "stop after this long [s] (0: until closed, Ctrl-C or SIGTERM)");
  cmd->add_flag("--headless", a->headless, "no window: process frames and print a summary");
  cmd->add_option("--record", a->record, "record the session into this new folder (docs/recording.md)");
  CLI::Option* record_frames = cmd->add_option("--record-frames", a->record_frames,
                  "video: camera.mp4 (H.264: small, lossy); mjpg: camera.avi (Motion-JPEG: larger, "
                  "nearly lossless); png: frames/NNNNNN.png (lossless: replay reproduces the fits exactly)")
      ->check(CLI::IsMember({"video", "mjpg", "png"}))
      ->capture_default_str();
  cmd->add_option("--screenshot", a->screenshot,
                  "window: save the window's pixels to this PNG just before exiting (tests)");
  return [a, record_frames] {
    require_range(a->seconds, 0, 86400, "--seconds", "s");
    if (a->record.empty()) refuse_given(record_frames, "with --record DIR (it chooses how the frames are recorded)");
    if (!a->screenshot.empty()) {
      if (a->headless) throw UsageError("--screenshot: saves the window's pixels; there is no window with --headless");
      check_output_file(a->screenshot, "--screenshot", "a PNG file");
    }
    if (!a->record.empty()) {
      check_output_dir(a->record, "--record");
      session::check_new_recording_folder(a->record);  // before the device and camera start
    }
    SignalScope signals;  // from the start: a signal during start-up ends the session once it runs
    const session::LiveConfig cfg = session::load_live_config(a->config);
    session::LiveSessionOptions opt;
    opt.record_dir = a->record;
    opt.record_frames = a->record_frames == "png"    ? session::FrameStore::kPng
                        : a->record_frames == "mjpg" ? session::FrameStore::kMjpg
                                                     : session::FrameStore::kVideo;

    if (!a->headless) return run_gui(cfg, opt, a->seconds, a->screenshot, g_signal);

    auto ctx_r = render::Context::create_headless();
    if (!ctx_r) throw SpidarError("OpenGL: " + ctx_r.error().message);
    auto context = std::move(ctx_r).value();
    auto session = session::LiveSession::create(cfg, *context, opt);
    std::cerr << "spidar-mr run: " << cfg.source << ": device " << cfg.backend << ", camera "
              << cfg.camera_source << " " << cfg.width << "x" << cfg.height << ", compositor "
              << cfg.compositor << (a->record.empty() ? "" : ", recording to " + a->record)
              << " (headless; Ctrl-C stops)\n";
    session->start();
    std::string ended_by = "seconds";
    double next_report = 1.0;
    while (true) {
      if (g_signal.load() != 0) {
        ended_by = g_signal.load() == SIGINT ? "SIGINT" : "SIGTERM";
        break;
      }
      if (a->seconds > 0 && session->seconds() >= a->seconds) break;
      if (!session->running()) {
        ended_by = session->camera_ended() ? "camera ended" : "device stopped";
        break;
      }
      if (!session->step()) session->wait_for_frame(core::monotonic_ns() + 5'000'000);
      if (session->seconds() >= next_report) {
        next_report += 1.0;
        const auto& h = session->history();
        std::cerr << "  t " << static_cast<int>(session->seconds()) << " s  frames " << session->frames()
                  << "  IoU " << (h.empty() ? 0.0 : h.back().iou) << "\n";
      }
    }
    const double wall = session->seconds();
    session->stop();
    const auto j = summary_json(*session, ended_by, wall);
    require_finite_json(j, "run's summary");
    std::cout << session::json_text(j, 2) << "\n";
    return live_exit_code(*session, ended_by);
  };
}

}  // namespace spidar::app
