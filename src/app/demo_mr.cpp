// spidar-mr demo (rubiks scenario, `make demo`): the whole mixed-reality system on the simulated
// rig. A scripted user with their own hands turns the Rubik's cube's top layer twice with the
// right hand while the left hand holds the cube; the simulated SPIDAR-8 measures the fingertips
// and displays the contact forces (servo thread ↔ physics thread); a synthetic camera films the
// real hands over the blue screen; the frame loop fits both model hands to the strings and the
// image, renders the virtual world, composites the real hands into it, and measures everything
// against the ground truth.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include "cli_support.hpp"
#include "demo.hpp"
#include "demo_mr_report.hpp"
#include "progress.hpp"
#include "signal_scope.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/scripted_task.hpp"
#include "spidar/session/servo_timing.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/physics/mujoco_log.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/model_ceiling.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/sim/user_hands.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/vision_config.hpp"

namespace spidar::app {

namespace fs = std::filesystem;

int run_mr_demo(const DemoOptions& o) {
  // Ctrl-C / SIGTERM end the run early but cleanly: the video is finished and the report written.
  SignalScope signals;
  // --- inputs (all checked before anything starts) ---
  const auto cfg = strings::load_device_config(resolve_data_path(o.config));
  if (cfg.fingers.size() != 8) throw UsageError("--config: the rubiks demo needs 8 fingers");
  const std::string scene_path = resolve_data_path(o.scene);
  const std::string hand_path = resolve_data_path(o.user_hand);
  const auto truth_models = session::hand_models(hand_path, o.user_profile, true);
  const auto models = session::hand_models(resolve_data_path("configs/hands.yaml"), o.model_profile, false);
  const vision::Camera camera = session::scaled_camera(
      vision::load_camera_file(resolve_data_path(o.camera)).camera, o.width, o.height);
  const auto vision_cfg = vision::load_vision_config(resolve_data_path("configs/vision.yaml"));
  const auto reg_root = core::ConfigNode::LoadFile(resolve_data_path("configs/registration.yaml"));
  const auto reg_params = registration::parse_registration_params(reg_root["registration"]);
  auto mode = render::parse_composite_mode(o.compositor);
  if (!mode) throw UsageError("--compositor: " + mode.error().message);

  physics::WorldParams wp;
  auto world_r = physics::World::Load(scene_path, wp);
  if (!world_r) throw UsageError("--scene: " + world_r.error().message);
  auto world = std::move(world_r).value();
  auto cube_r = physics::RubiksCube::Attach(*world);
  std::optional<physics::RubiksCube> cube;
  if (cube_r) cube = std::move(cube_r).value();
  fs::create_directories(o.out);
  fs::create_directories(fs::path(o.out) / "keyframes");

  Pose X_cube0;
  auto task = session::make_scripted_task(*world, cube, wp.proxy.radius, truth_models, &X_cube0);
  const double seconds = o.seconds > 0 ? o.seconds : task->params().duration;

  // --- threads: simulated device ↔ servo loop ↔ physics ---
  device::SimulatedSpidarParams dp;
  dp.seed = o.seed;
  device::SimulatedSpidar dev(cfg, dp, task);
  device::ServoConfig servo;
  servo.rate_hz = o.rate_hz;
  servo.force_timeout_s = 0.05;  // the physics thread's steps may come late on a busy machine
  // Late cycles and stale forces degrade the display and are counted; the safe state latches
  // only past the stall limit (ServoConfig::stall_limit_s, docs/realtime.md), as on real devices.
  auto bridge = std::make_shared<sim::HapticForces>(wp.coupling, servo.rate_hz);
  sim::PhysicsThread physics(*world, *bridge);
  physics.set_snapshot_proxies(false);
  physics.set_realtime_priority(60);  // above the rendering threads, below the servo loop
  session::CubeMonitor monitor(&cube, X_cube0);
  if (cube) task->track(&monitor.pose());  // the user watches the cube
  physics.set_before_step([&monitor](physics::World& w) { monitor.before_step(w); });
  device::ServoLoop loop(dev, cfg, servo, bridge);

  // --- the frame side: GL, synthetic camera, user hands, pipeline ---
  auto ctx_r = o.window ? render::Context::create_window({o.width, o.height, "spidar-mr demo"})
                        : render::Context::create_headless();
  if (!ctx_r) throw SpidarError("OpenGL: " + ctx_r.error().message);
  auto context = std::move(ctx_r).value();
  sim::SyntheticCameraParams cam_params;
  cam_params.seed = o.seed;

  pipeline::FramePipelineParams pp;
  pp.chroma_key = vision_cfg.chroma_key;
  pp.bracelet = vision_cfg.bracelet;
  pp.registration = reg_params;
  pp.registration.silhouette_term = o.silhouette;
  pp.compositor.mode = *mode;
  for (int h = 0; h < 2; ++h) {
    const auto n = task->nominal(0.0, h == 0 ? hand::Side::kLeft : hand::Side::kRight);
    pp.initial_r_W_hand[h] = n.r_W_hand();
  }
  auto pipe_r = pipeline::FramePipeline::create(*context, camera, models, pp);
  if (!pipe_r) throw UsageError(pipe_r.error().message);
  auto pipe = std::move(pipe_r).value();
  // The comparison: the same registration with the silhouette term switched the other way.
  pipeline::FramePipelineParams pp_alt = pp;
  pp_alt.registration.silhouette_term = !o.silhouette;
  auto alt_r = pipeline::FramePipeline::create(*context, camera, models, pp_alt);
  if (!alt_r) throw UsageError(alt_r.error().message);
  auto alt = std::move(alt_r).value();

  // The model's ceiling: its own skin at the user's true pose and sizes (every compared frame).
  auto ceiling_r = sim::ModelCeiling::create(*context, camera, truth_models, pp.model_skin);
  if (!ceiling_r) throw SpidarError(ceiling_r.error().message);
  auto ceiling = std::move(ceiling_r).value();

  std::unique_ptr<render::VideoOutput> video;
  if (o.video) {
    auto v = render::VideoOutput::open((fs::path(o.out) / "mixed_reality.mp4").string(), o.width,
                                       o.height, o.fps);
    if (!v) throw SpidarError(v.error().message);
    video = std::move(v).value();
  }

  std::cout << "spidar-mr demo: mixed-reality Rubik's cube on a simulated " << cfg.name << "\n"
            << "  scene " << scene_path << (cube ? "" : " (no cube: reaching for the nearest object)")
            << "\n  user hands '" << o.user_profile << "' from " << hand_path << " ("
            << truth_models[0].shape.dimensions.length * 1e3 << " mm; model "
            << models[0].shape.dimensions.length * 1e3 << " mm), camera " << o.width << "x"
            << o.height << " at " << o.fps << " fps, compositor " << o.compositor
            << ", registration " << (o.silhouette ? "joint-balls + silhouette" : "joint-balls (paper)")
            << "\n  servo " << servo.rate_hz << " Hz, physics " << 1.0 / world->timestep()
            << " Hz in its own thread\n\n";

  // --- warm-up, before the clock starts ---
  // The first frame through each pipeline pays one-off costs (GL programs and buffers, hand
  // skins, workspaces: ~130 ms each, measured), which in the run would drop the camera's first
  // ~9 frames. A blank blue screen with the fingertips where the script starts; both fits are
  // then reset, so the run's first frame is a cold start as before.
  {
    const auto& rgb = cam_params.screen_rgb;
    const cv::Mat blank(o.height, o.width, CV_8UC3,
                        cv::Scalar(255.0 * rgb[2], 255.0 * rgb[1], 255.0 * rgb[0]));
    std::vector<Vec3> goals(8);
    task->goals(0.0, goals);
    device::FingertipSample tips;
    tips.finger_count = 8;
    for (int f = 0; f < 8; ++f) tips.p_W[f] = {goals[f].x(), goals[f].y(), goals[f].z()};
    SceneSnapshot s0;
    world->snapshot(s0, false);
    pipeline::FrameResult warm;
    for (pipeline::FramePipeline* p : {pipe.get(), alt.get()}) {
      if (auto st = p->process(blank, tips, s0, &warm); !st) throw SpidarError(st.error().message);
      p->reset();
    }
  }

  // --- run ---
  if (auto st = dev.open(); !st.ok()) throw UsageError(st.error().message);
  const std::int64_t t_open = core::monotonic_ns();
  physics.start();
  if (auto st = loop.start(); !st.ok()) throw UsageError(st.error().message);

  // The camera films in its own thread; the ground truth comes from the simulated device.
  std::vector<device::FingertipSample> truth_buf(1000);
  sim::TruthAt truth_at = [&dev, &truth_buf](std::int64_t t_ns, std::span<Vec3> out) {
    const std::size_t n = dev.truth_samples(truth_buf.data(), truth_buf.size());
    const auto s = device::interpolate_samples({truth_buf.data(), n}, t_ns);
    if (!s) return false;
    for (std::size_t f = 0; f < out.size() && f < 8; ++f) out[f] = Vec3(s->p_W[f][0], s->p_W[f][1], s->p_W[f][2]);
    return true;
  };
  sim::CameraThreadParams ctp;
  ctp.fps = o.fps;
  ctp.t0_ns = t_open;
  auto cam_r = sim::CameraThread::start(camera, truth_models, cam_params, *task, truth_at, ctp);
  if (!cam_r) throw SpidarError(cam_r.error().message);
  auto camera_thread = std::move(cam_r).value();

  std::vector<device::FingertipSample> servo_buf(1000);
  SceneSnapshot scene;
  pipeline::FrameResult result, alt_result;
  sim::FrameTruthWorkspace ws;
  MrTrace trace;
  Progress progress(seconds, std::cerr);
  const std::array<double, 5> keyframe_times{1.9, 3.0, 4.5, 8.5, 10.2};
  std::size_t next_keyframe = 0;
  std::vector<std::pair<std::string, cv::Mat>> keyframes;  // path, montage
  std::int64_t last_servo_t = 0;
  constexpr int kCompareEvery = 5;
  int frame_index = 0;

  std::string ended_by = "completed";
  while (loop.running()) {
    if (SignalScope::received() != 0) {
      ended_by = SignalScope::ended_by(ended_by);
      break;
    }
    if (!camera_thread->take()) {  // wait for the next frame
      if (core::ns_to_s(core::monotonic_ns() - t_open) > seconds + 1.0) break;
      std::this_thread::sleep_for(std::chrono::microseconds(500));
      continue;
    }
    const sim::FilmedFrame& filmed = camera_thread->frame();
    const sim::SyntheticFrame& frame = filmed.frame;
    const std::int64_t t_exp = filmed.t_exposure_ns;
    const double t_script = filmed.t_script_s;
    if (t_script > seconds) break;
    const std::size_t ns = loop.newest_samples(servo_buf.data(), servo_buf.size());
    const auto measured = device::interpolate_samples({servo_buf.data(), ns}, t_exp);
    if (!measured) continue;  // no servo samples around the exposure (a stall): skip the frame
    const auto& truth = filmed.truth;
    const double film_ms = filmed.film_ms;
    physics.snapshots().update();
    scene = physics.snapshots().front();

    if (auto st = pipe->process(frame.bgr, *measured, scene, &result); !st)
      throw SpidarError(st.error().message);
    const std::int64_t done = core::monotonic_ns();
    // The comparison registration runs every frame (it must track), its rendering and metrics
    // every kCompareEvery-th frame (a sample of the run; it costs as much as the main pipeline).
    const bool compare = frame_index % kCompareEvery == 0;
    if (auto st = alt->process(frame.bgr, *measured, scene, &alt_result, !compare); !st)
      throw SpidarError(st.error().message);

    // --- metrics against the ground truth ---
    MrFrame m;
    m.t_s = t_script;
    m.latency_ms = core::ns_to_s(done - t_exp) * 1e3;
    m.pipeline_ms = result.timings.total_ms;
    m.registration_ms = result.timings.registration_ms;
    m.preprocess_ms = result.timings.key_ms + result.timings.bracelet_ms + result.timings.distance_ms;
    m.stages = result.timings;
    m.film_ms = film_ms;
    auto main_m = sim::measure_frame(frame, result, *mode, models, truth_models, truth, camera, &ws);
    if (!main_m) throw SpidarError(main_m.error().message);
    m.truth[0] = *main_m;
    if (compare) {
      auto alt_m = sim::measure_frame(frame, alt_result, *mode, models, truth_models, truth, camera, &ws);
      if (!alt_m) throw SpidarError(alt_m.error().message);
      m.truth[1] = *alt_m;
      m.compared = true;
      auto c = ceiling->iou(filmed.truth, frame.hand_only);
      if (!c) throw SpidarError(c.error().message);
      m.ceiling_iou = *c;
      m.ceiling_measured = true;
    }
    ++frame_index;
    for (int h = 0; h < 2; ++h) {
      m.iterations[h] = result.fits[h].iterations;
      m.truth_cap_residual_mm[h] = filmed.cap_residual_m[h] * 1e3;
    }
    if (auto s = monitor.status().read()) {
      m.lift_mm = s->lift * 1e3;
      m.u_angle_deg = s->u_angle * 180 / M_PI;
      m.d_angle_deg = s->d_angle * 180 / M_PI;
      m.turns = s->turns;
    }
    for (int f = 0; f < 8; ++f) {
      m.force_n[f] = Vec3(measured->f_W[f][0], measured->f_W[f][1], measured->f_W[f][2]).norm();
    }
    {  // servo timing since the last frame, from the published samples
      const session::ServoTiming st = session::servo_timing_since({servo_buf.data(), ns}, servo.rate_hz, &last_servo_t);
      m.servo_rate_hz = st.rate_hz;
      m.servo_jitter_max_us = st.jitter_max_us;
    }
    m.truth_ms = core::ns_to_s(core::monotonic_ns() - done) * 1e3;
    trace.frames.push_back(m);
    const std::int64_t t_out0 = core::monotonic_ns();
    // --- output ---
    cv::Mat& shown = result.composite;
    if (video) {
      if (auto st = video->write(shown); !st) throw SpidarError(st.error().message);
    }
    if (next_keyframe < keyframe_times.size() && t_script >= keyframe_times[next_keyframe]) {
      char name[64];
      std::snprintf(name, sizeof name, "keyframe_%d_t%04.1fs.png", static_cast<int>(next_keyframe) + 1, t_script);
      const std::string caption = "t = " + std::to_string(t_script).substr(0, 4) + " s, " +
                                  sim::RubiksTask::phase(t_script) + ", IoU " +
                                  std::to_string(m.truth[0].iou).substr(0, 5);
      // Composed now (the frame's buffers are reused), encoded after the run: a PNG takes tens of
      // milliseconds, which here would drop camera frames.
      keyframes.emplace_back((fs::path(o.out) / "keyframes" / name).string(),
                             sim::keyframe_montage(frame.bgr, result, *mode, models, camera, caption));
      ++next_keyframe;
    }
    if (o.window) (void)pipe->present(*context, shown);
    trace.frames.back().output_ms = core::ns_to_s(core::monotonic_ns() - t_out0) * 1e3;
    {
      std::ostringstream st;
      st << std::fixed << std::setprecision(1) << "t " << t_script << "/" << seconds << " s  "
         << std::left << std::setw(24) << sim::RubiksTask::phase(t_script) << std::right
         << std::setprecision(3) << " IoU " << m.truth[0].iou << std::setprecision(1)
         << "  tip " << 0.5 * (m.truth[0].fingertip_mm[0] + m.truth[0].fingertip_mm[1])
         << " mm  occlusion " << m.truth[0].occlusion_pct << " % (paper "
         << m.truth[0].occlusion_pct_paper << " %)  layer " << m.u_angle_deg << " deg";
      progress.update(t_script, st.str());
    }

  }
  const double wall_s = core::ns_to_s(core::monotonic_ns() - t_open);
  camera_thread->stop();
  const int dropped = static_cast<int>(camera_thread->filmed()) - static_cast<int>(trace.frames.size());
  if (!camera_thread->error().empty()) throw SpidarError(camera_thread->error());
  loop.stop();
  physics.stop();
  dev.close();
  if (video) video->close();
  progress.finish();
  for (const auto& [path, montage] : keyframes) {
    if (auto st = render::write_png(path, montage); !st) throw SpidarError(st.error().message);
  }

  // --- report ---
  MrSummary summary;
  summary.seconds = seconds;
  summary.wall_s = wall_s;
  summary.dropped = dropped;
  summary.servo = loop.stats();
  summary.physics = physics.stats();
  if (auto s = monitor.status().read()) {
    summary.turns = s->turns;
    summary.solved = s->solved;
  }
  summary.has_cube = cube.has_value();
  summary.facelets = cube ? cube->facelets() : "";
  if (cube) {
    for (char f : std::string("UDFBRL")) summary.face_deg[f] = cube->face_angle(f) * 180 / M_PI;
  }
  summary.video_path = video ? video->path() : "";
  summary.video_format = video ? render::video_format_name(video->format()) : "";
  summary.main_silhouette = o.silhouette;
  summary.compositor = o.compositor;
  summary.width = o.width;
  summary.height = o.height;
  summary.scene = scene_path;
  summary.user_hand = hand_path;
  summary.user_length_m = truth_models[0].shape.dimensions.length;
  summary.user_width_m = truth_models[0].shape.dimensions.width;
  summary.ended_by = ended_by;
  summary.mujoco_warning_kinds = world->warning_counts();
  const physics::MujocoWarnings mj = physics::mujoco_warnings();
  summary.mujoco_warnings = mj.count;
  if (mj.count > 0) {  // MuJoCo's own log, here rather than MUJOCO_LOG.TXT in the working directory
    const fs::path log = fs::path(o.out) / "mujoco_log.txt";
    std::ofstream f(log);
    f << mj.count << " MuJoCo warning(s) in this run; the last " << mj.messages.size() << ":\n";
    for (const auto& m : mj.messages) f << m << "\n";
    if (!f) throw SpidarError("cannot write " + log.string());
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
