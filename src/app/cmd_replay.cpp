// spidar-mr replay DIR: re-runs registration and compositing offline on a recording made by
// `run --record DIR` (docs/recording.md), and writes report.json, a video and plots. Wiring only:
// a session::RecordingRig (the recorded frames with their fingertip samples and scene poses), a
// session::Session (the same FramePipeline path as the live run) and its sinks (the replay's
// scorer, the video). The recording is read and checked by session::read_recording (a damaged or
// incomplete one is refused, exit 2, naming file:line:column).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "spidar/session/live_config.hpp"
#include "spidar/session/live_session.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/output_sinks.hpp"
#include "spidar/session/recording_rig.hpp"
#include "spidar/session/replay_report.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/session.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::app {
namespace {

namespace fs = std::filesystem;

/// Replays a recording; returns the report (also written to out/report.json).
nlohmann::json replay_recording(const std::string& dir, const std::string& out, bool video_out) {
  const fs::path d(dir);
  session::Recording rec = session::read_recording(dir);
  const session::LiveConfig cfg = session::load_live_config(rec.config_path, false);
  if (rec.meta.width != cfg.width || rec.meta.height != cfg.height)
    throw UsageError((d / "session.json").string() + ": size " + std::to_string(rec.meta.width) + "x" +
                     std::to_string(rec.meta.height) + " differs from config.yaml's " +
                     std::to_string(cfg.width) + "x" + std::to_string(cfg.height));
  if (rec.frames.empty()) throw UsageError((d / "frames.csv").string() + ": no frames recorded");
  const std::string frames_file = rec.meta.store == session::FrameStore::kPng ? "frames/*.png" : rec.video_path;

  auto ctx_r = render::Context::create_headless();
  if (!ctx_r) throw SpidarError("OpenGL: " + ctx_r.error().message);
  auto context = std::move(ctx_r).value();
  const vision::Camera camera =
      session::scaled_camera(vision::load_camera_file(cfg.camera_calibration).camera, cfg.width, cfg.height);
  const auto models = session::hand_models(cfg.hands_file, cfg.model_profile, false);
  // The scene's structure from its MJCF (as the live run loaded it), its poses from scene.csv.
  auto scene_r = session::Scene::load(cfg.scene, session::hand_models(cfg.hands_file, cfg.user_profile, true));
  if (!scene_r) throw UsageError(cfg.scene + ": " + scene_r.error().message);
  SceneSnapshot shapes;
  (*scene_r)->world->snapshot(shapes, false);
  if (!rec.scene.front().empty() && rec.scene.front().size() != shapes.shapes.size())
    throw UsageError((d / "scene.csv").string() + ": " + std::to_string(rec.scene.front().size()) +
                     " shapes per frame, the scene has " + std::to_string(shapes.shapes.size()) + " (" +
                     cfg.scene + ": was it changed since the recording?)");
  const auto frames = rec.frames.size();
  const std::array<Vec3, 2> r0 = rec.meta.initial_r_W_hand;
  session::RecordingRig rig(std::move(rec), cfg.width, cfg.height);

  session::SessionParams sp;
  sp.warm_up = false;  // the recorded fits started cold from the recording's start rotations
  sp.frame_fifo_priority = 0;  // offline, as fast as it goes: no real-time priority to hold a core with
  sp.pipeline = session::live_pipeline_params(cfg, r0);
  auto session = session::Session::create(rig, **scene_r, *context, camera, models, sp);
  session::ReplayScorer scorer(rig);
  session->add_sink(scorer);
  fs::create_directories(out);
  std::unique_ptr<render::VideoOutput> video;
  std::unique_ptr<session::VideoSink> video_sink;
  if (video_out) {
    auto v = render::VideoOutput::open((fs::path(out) / "replay.mp4").string(), cfg.width, cfg.height, cfg.fps);
    if (!v) throw SpidarError(v.error().message);
    video = std::move(v).value();
    video_sink = std::make_unique<session::VideoSink>(*video);
    session->add_sink(*video_sink);
  }
  session->run();
  if (scorer.figures().t.empty())
    throw UsageError("replay " + dir + ": none of the " + std::to_string(frames) +
                     " recorded frames decoded (" + frames_file + " damaged?)");
  return session::write_replay_report(out, rig, scorer, video ? video->path() : "");
}

}  // namespace

Action add_replay(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay",
                                 "Re-run registration and compositing on a recording (run --record); "
                                 "writes report.json, replay.mp4 and plots");
  struct Args {
    std::string dir, out;
    bool video = true;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("dir", a->dir, "recording folder")->required();
  cmd->add_option("--out", a->out, "output folder (default: DIR/replay)");
  cmd->add_flag("!--no-video", a->video, "do not write replay.mp4");
  return [a] {
    const std::string out = a->out.empty() ? (fs::path(a->dir) / "replay").string() : a->out;
    check_output_dir(out, a->out.empty() ? "--out (DIR/replay)" : "--out");
    const auto j = replay_recording(a->dir, out, a->video);
    std::cout << session::json_text(j, 2) << "\n";
    return 0;
  };
}

}  // namespace spidar::app
