// spidar-mr demo (rubiks scenario, `make demo`): the whole mixed-reality system on the simulated
// rig. A scripted user with their own hands turns the Rubik's cube's top layer twice with the
// right hand while the left hand holds the cube; the simulated SPIDAR-8 measures the fingertips
// and displays the contact forces (servo thread ↔ physics thread); a synthetic camera films the
// real hands over the blue screen; the frame loop fits both model hands to the strings and the
// image, renders the virtual world, composites the real hands into it, and measures everything
// against the ground truth. Wiring only: a SimulatedRig, a Session and its sinks.
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli_support.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/core/units.hpp"
#include "spidar/device/workspace.hpp"
#include "spidar/registration/fingertip_end.hpp"
#include "demo.hpp"
#include "spidar/session/run_report.hpp"
#include "progress.hpp"
#include "signal_scope.hpp"
#include "spidar/physics/mujoco_log.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/async_sinks.hpp"
#include "spidar/session/output_sinks.hpp"
#include "spidar/session/rig.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/session.hpp"
#include "spidar/session/truth_scorer.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::app {

namespace fs = std::filesystem;
using session::MrFrame;
using session::MrSummary;
using session::MrTrace;
using session::write_mr_report;

namespace {

/// The progress line: script phase, IoU, fingertip error, occlusion, the cube's top layer (in a
/// scene without a cube, the held object's lift).
std::string status_line(const MrFrame& m, const sim::RubiksTask& task) {
  std::ostringstream st;
  st << std::fixed << std::setprecision(1) << "t " << m.t_s << " s  "
     << std::left << std::setw(24) << task.phase(m.t_s) << std::right
     << std::setprecision(3) << " IoU ";
  // No hand in view: no IoU to show (1 by definition for two empty silhouettes).
  if (m.truth[0].scored_in_image()) st << m.truth[0].iou;
  else st << "n/a  ";
  st << std::setprecision(1)
     << "  tip " << 0.5 * (m.truth[0].fingertip_mm[0] + m.truth[0].fingertip_mm[1])
     << " mm  occlusion " << m.truth[0].occlusion_pct << " % (paper "
     << m.truth[0].occlusion_pct_paper << " %)";
  if (task.params().has_cube) st << "  layer " << m.u_angle_deg << " deg";
  else st << "  lift " << m.lift_mm << " mm";
  return st.str();
}

}  // namespace

int run_mr_demo(const DemoOptions& o) {
  // Ctrl-C / SIGTERM end the run early but cleanly: the video is finished and the report written.
  SignalScope signals;
  // --- inputs (all checked before anything starts) ---
  require_path(o.user_hand, "--user-hand", "a hands YAML file");
  require_path(o.scene, "--scene", "an MJCF scene file");
  require_path(o.camera, "--camera", "a camera YAML file");
  require_path(o.config, "--config", "a device config YAML file");
  check_output_dir(o.out, "--out");  // made once the inputs are known good (a refused run leaves nothing)
  const auto cfg = strings::load_device_config(resolve_data_path(o.config));
  if (cfg.fingers.size() != 8) throw UsageError("--config: the rubiks demo needs 8 fingers");
  const std::string scene_path = resolve_data_path(o.scene);
  const std::string hand_path = resolve_data_path(o.user_hand);
  std::string user_profile;  // the profile used: o.user_profile, else the file's first
  const auto truth_models = session::hand_models(hand_path, o.user_profile, true, &user_profile);
  const auto models = session::hand_models(resolve_data_path("configs/hands.yaml"), o.model_profile, false);
  const vision::Camera calibrated = vision::load_camera_file(resolve_data_path(o.camera)).camera;
  // A calibration with lens distortion: the synthetic camera films through that lens, and the
  // session undistorts its frames into the lens's pinhole camera, as with a real camera
  // (vision::LensUndistortion). A lens that cannot be undistorted is refused as the file loads.
  {
    // Scaling a calibration to another aspect ratio would make its pixels non-square.
    const double a = static_cast<double>(o.width) / o.height;
    const double a0 = static_cast<double>(calibrated.width()) / calibrated.height();
    if (std::abs(a / a0 - 1.0) > 0.01)
      throw UsageError("--width/--height: " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                       " is not the shape of the camera's calibration, " + std::to_string(calibrated.width()) +
                       "x" + std::to_string(calibrated.height()) + " (--camera " + o.camera +
                       "): give a size of the same aspect ratio, e.g. " +
                       std::to_string(static_cast<int>(std::lround(o.height * a0))) + "x" + std::to_string(o.height));
  }
  const vision::Camera camera = session::scaled_camera(calibrated, o.width, o.height);
  auto mode = render::parse_composite_mode(o.compositor);
  if (!mode) throw UsageError("--compositor: " + mode.error().message);
  // The scripted user plays until its task is done (retries included), by --seconds at most.
  auto scene_r = session::Scene::load(scene_path, truth_models, {o.seconds, o.shaped_fingers, o.ring_on_side, o.fit_margin_rad});
  if (!scene_r) throw UsageError("--scene: " + scene_r.error().message);
  session::Scene& scene = *scene_r.value();
  const auto& cube = scene.cube;
  const sim::RubiksTask& task = *scene.task;
  const double seconds = task.params().deadline;
  // The object must be where the device's strings can follow the fingers to it: inside the frame
  // its fulcrums span (a fingertip solved outside it latches the workspace fault at once).
  {
    const Vec3& p = task.params().p_W_cube;
    const auto ws = device::device_workspace(cfg, 0.0);
    if (const auto ex = device::workspace_excess(ws, {p.x(), p.y(), p.z()}); ex.distance_m > 0) {
      const char* axis = ex.axis == 0 ? "x" : ex.axis == 1 ? "y" : "z";
      std::ostringstream m;
      m << std::fixed << std::setprecision(3) << "--scene: the object to reach for, at (" << p.x() << ", " << p.y()
        << ", " << p.z() << ") m, lies " << ex.distance_m << " m beyond the device's frame along " << axis
        << " (its fulcrums span [" << ws.lo_W[ex.axis] << ", " << ws.hi_W[ex.axis] << "] m, --config "
        << o.config << ")";
      throw UsageError(m.str());
    }
  }

  session::SessionParams sp;
  sp.servo.rate_hz = o.rate_hz;
  sp.servo.idle_spin = o.idle_spin == 1;  // off unless asked: it slows the frame pipeline
  sp.servo.force_timeout_s = 0.05;  // the physics thread's steps may come late on a busy machine
  // Late cycles and stale forces degrade the display and are counted; the safe state latches
  // only past the stall limit (ServoConfig::stall_limit_s, docs/realtime.md), as on real devices.
  sp.pipeline = session::pipeline_params(resolve_data_path("configs/vision.yaml"),
                                         resolve_data_path("configs/registration.yaml"), o.silhouette,
                                         *mode, scene.initial_r_W_hand());
  // The demo personalises the hands' sizes online (registration/shape_estimator.hpp) unless told
  // not to; `run` follows configs/registration.yaml (off: a recording does not yet store the size
  // estimates, so a replay could not reproduce fits made with them).
  sp.pipeline.personalise_shape = !o.fixed_hand_size;
  sp.compare = true;  // the same registration with the silhouette term switched the other way
  sp.defer_compare = true;  // fitted and pictured on the output thread (AsyncSinks::compare)
  // Its picture (and the model ceiling, measured on the same frames) every 10th frame: 30 to 36
  // frames of a run, a sample of every phase, at a third of the output thread's work.
  sp.compare_every = 10;
  // The other compositor's picture (the paper's, for the report's comparison) on the output
  // thread too (AsyncSinks::compose_others): the frame thread composes only what is shown.
  sp.pipeline.other_composite = false;
  sp.seconds = seconds;
  sp.end_with_script = true;

  // --- the outputs' folder (the inputs are good), the rig, the session and its sinks ---
  make_output_dir(o.out, "--out");
  make_output_dir((fs::path(o.out) / "keyframes").string(), "--out");
  auto ctx_r = o.window ? render::Context::create_window({o.width, o.height, "spidar-mr demo"})
                        : render::Context::create_headless();
  if (!ctx_r) throw SpidarError("OpenGL: " + ctx_r.error().message);
  auto context = std::move(ctx_r).value();
  session::SimulatedRigParams rp;
  rp.seed = o.seed;
  rp.fps = o.fps;
  rp.bending_wrists = o.bending_wrists;
  session::SimulatedRig rig(cfg, scene, camera, truth_models, rp);
  auto run = session::Session::create(rig, scene, *context, camera, models, sp);
  // The camera the pipelines, the ground truth and the pictures share: the calibration's, or its
  // lens's pinhole camera.
  const vision::Camera& seen = run->camera();

  session::TruthScorer scorer(seen, truth_models, sp.pipeline);
  // The video is opened on the output thread (VideoSink::on_start), so that the encoder's threads
  // run at its niceness too.
  std::unique_ptr<session::VideoSink> video_sink;
  if (o.video)
    video_sink = std::make_unique<session::VideoSink>((fs::path(o.out) / "mixed_reality.mp4").string(),
                                                      o.width, o.height, o.fps);
  session::KeyframeSink keyframes(
      (fs::path(o.out) / "keyframes").string(), {1.9, 3.0, 4.5, 8.5, 10.2}, *mode, seen,
      [&scorer, &task](const session::FrameEvent& e) {
        return "t = " + std::to_string(e.t_s).substr(0, 4) + " s, " + task.phase(e.t_s) +
               ", IoU " + std::to_string(scorer.trace().frames.back().truth[0].iou).substr(0, 5);
      });
  session::FunctionSink window([&](const session::FrameEvent& e) {
    if (o.window) (void)run->pipeline().present(*context, e.result->composite);
  });
  std::vector<session::FrameSink*> outputs;
  if (video_sink) outputs.push_back(video_sink.get());
  outputs.push_back(&keyframes);
  session::SinkGroup output(outputs);  // timed: the report's output_ms
  Progress progress(task.params().duration, std::cerr);  // in script time (retries replay some)
  session::FunctionSink progress_sink(
      [&](const session::FrameEvent&) {
        scorer.set_output_ms(output.last_ms());
        const MrFrame& m = scorer.trace().frames.back();
        progress.update(task.script_time(m.t_s), status_line(m, task));
      },
      [&](const session::SessionSummary&) { progress.finish(); });
  // The window on the frame thread (its GL context lives there); scoring, video, keyframes and
  // the progress line on the output thread, off the pipeline's critical path, at nice 5: below
  // the frame thread (−5), but not so far below another process's nice 0 that it starves and the
  // frame thread waits for its slots (one core busy, seeds 1–3: 7.0–9.8 % of the frames dropped
  // at nice 10, 0.55–2.2 % at 5; quiet, latency p95 28–29 ms at 5; docs/measurements.md).
  session::AsyncSinks off_path({&scorer, &output, &progress_sink}, 3, 5);
  off_path.compare(seen, models, sp.pipeline, run->warm_up_frame());
  off_path.compose_others(sp.pipeline.compositor);
  run->add_sink(window);
  run->add_sink(off_path);

  std::cout << "spidar-mr demo: mixed-reality Rubik's cube on a simulated " << cfg.name << "\n"
            << "  scene " << scene_path << (cube ? "" : " (no cube: reaching for the nearest object)")
            << "\n  user hands '" << user_profile << "'"
            << (user_profile != o.user_profile ? " (no '" + o.user_profile + "' profile: the file's first)" : std::string())
            << " from " << hand_path << " ("
            << truth_models[0].shape.dimensions.length * 1e3 << " mm; model "
            << models[0].shape.dimensions.length * 1e3 << " mm), camera " << o.width << "x"
            << o.height << " at " << o.fps << " fps, compositor " << o.compositor
            << ", registration " << (o.silhouette ? "joint-balls + silhouette" : "joint-balls (paper)")
            << "\n  servo " << sp.servo.rate_hz << " Hz, physics " << 1.0 / scene.world->timestep()
            << " Hz in its own thread\n\n";

  // --- run (the warm-up before the clock starts) ---
  const session::SessionSummary end = run->run([]() -> std::optional<std::string> {
    if (SignalScope::received() == 0) return std::nullopt;
    return SignalScope::ended_by("completed");
  });
  if (!end.camera_error.empty()) throw SpidarError(end.camera_error);
  const MrTrace& trace = scorer.trace();
  const std::string ended_by = end.ended_by;

  // --- report ---
  MrSummary summary;
  summary.seconds = end.t_last_s;
  summary.wall_s = end.wall_s;
  summary.thread_cpu = end.thread_cpu;
  summary.dropped = static_cast<int>(end.camera_frames) - static_cast<int>(trace.frames.size());
  summary.camera_skipped = static_cast<int>(end.camera_skipped);
  summary.output_waits = off_path.waits();
  summary.output_wait_ms = off_path.waited_ms();
  summary.frame_realtime = end.frame_realtime;
  summary.servo = end.servo;
  summary.physics = end.physics;
  if (auto s = scene.monitor->status().read()) {
    summary.turns = s->top_turns;
    summary.other_turns = s->turns - s->top_turns;
    summary.solved = s->solved;
  }
  summary.task = task.progress();
  summary.phases.reserve(trace.frames.size());
  for (const MrFrame& m : trace.frames) summary.phases.emplace_back(task.phase_kind(m.t_s));
  summary.has_cube = cube.has_value();
  summary.facelets = cube ? cube->facelets() : "";
  if (cube) {
    for (char f : std::string("UDFBRL")) summary.face_deg[f] = cube->face_angle(f) * 180 / units::kPi;
  }
  const render::VideoOutput* video = video_sink ? video_sink->video() : nullptr;
  summary.video_path = video ? video->path() : "";
  summary.video_format = video ? render::video_format_name(video->format()) : "";
  summary.main_silhouette = o.silhouette;
  summary.personalised = !o.fixed_hand_size;
  summary.shaped_fingers = o.shaped_fingers;
  summary.ring_on_side = o.ring_on_side;
  summary.fit_margin_rad = o.fit_margin_rad;
  summary.bending_wrists = o.bending_wrists;
  summary.compositor = o.compositor;
  summary.width = o.width;
  summary.height = o.height;
  summary.scene = scene_path;
  summary.user_hand = hand_path;
  summary.user_profile = user_profile;
  summary.user_length_m = truth_models[0].shape.dimensions.length;
  summary.user_width_m = truth_models[0].shape.dimensions.width;
  summary.user_cap_reach_m = registration::model_fingertip_reach_m(truth_models[0]);
  summary.ended_by = ended_by;
  summary.mujoco_warning_kinds = scene.world->warning_counts();
  const physics::MujocoWarnings mj = physics::mujoco_warnings();
  summary.mujoco_warnings = mj.count;
  if (mj.count > 0) {  // MuJoCo's own log, here rather than MUJOCO_LOG.TXT in the working directory
    const fs::path log = fs::path(o.out) / "mujoco_log.txt";
    std::ostringstream f;
    f << mj.count << " MuJoCo warning(s) in this run; the last " << mj.messages.size() << ":\n";
    for (const auto& m : mj.messages) f << m << "\n";
    core::write_file_atomic(log.string(), f.str());
    summary.mujoco_log = log.string();
  }
  const int code = write_mr_report(o.out, trace, summary, std::cout);
  if (summary.servo.faults != 0) {
    std::cerr << "spidar-mr demo: the servo loop latched " << device::fault_names(summary.servo.faults)
              << ": " << summary.servo.fault_message << " (the report is written; exit code "
              << kExitFault << ")\n";
  }
  if (SignalScope::received() != 0) {
    std::cerr << "spidar-mr demo: ended by " << ended_by << " after " << trace.frames.size()
              << " frames (video and report written)\n";
    return SignalScope::exit_code(code);
  }
  return summary.servo.faults != 0 ? kExitFault : code;
}

}  // namespace spidar::app
