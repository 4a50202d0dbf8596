#include "spidar/session/session.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>

#include "spidar/core/clock.hpp"
#include "spidar/core/realtime.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/sim/synthetic_camera.hpp"

namespace spidar::session {
namespace {
/// The longest the frame thread waits for a frame before it looks at the run's state again (an
/// interruption, the seconds, a stopped servo loop) [ns].
constexpr std::int64_t kFrameWaitNs = 5'000'000;
}  // namespace

Session::Session(Rig& rig, Scene& scene, render::Context& context, const SessionParams& params)
    : rig_(rig), scene_(scene), context_(context), params_(params) {}

Status validate(const SessionParams& params) {
  if (params.warm_results < 1 || params.warm_results > 32)
    return Error{"session: warm_results must be in 1..32, got " + std::to_string(params.warm_results)};
  if (params.frame_fifo_priority < 0 || params.frame_fifo_priority > 99)
    return Error{"session: frame_fifo_priority must be in 0..99 (0: none), got " +
                 std::to_string(params.frame_fifo_priority)};
  if (params.physics_priority < 0 || params.physics_priority > 99)
    return Error{"session: physics_priority must be in 0..99 (0: normal scheduling), got " +
                 std::to_string(params.physics_priority)};
  if (params.frame_nice < -20 || params.frame_nice > 19)
    return Error{"session: frame_nice must be in -20..19, got " + std::to_string(params.frame_nice)};
  return Ok{};
}

std::unique_ptr<Session> Session::create(Rig& rig, Scene& scene, render::Context& context,
                                         const vision::Camera& camera,
                                         const std::array<hand::HandModel, 2>& models,
                                         const SessionParams& params, device::Device* drive) {
  if (auto st = validate(params); !st) throw SpidarError(st.error().message);
  std::unique_ptr<Session> s(new Session(rig, scene, context, params));
  auto lens = vision::LensUndistortion::of(camera.intrinsics());
  if (!lens) throw SpidarError("camera: " + lens.error().message);
  s->lens_ = std::move(lens).value();
  s->camera_ = s->lens_ ? s->lens_->pinhole_camera(camera.X_CW()) : camera;
  // --- the haptic side: servo loop ↔ bridge ↔ physics thread (none when playing back) ---
  if (!rig.plays_back()) {
    HapticSideParams hp;
    hp.servo = params.servo;
    hp.physics_priority = params.physics_priority;
    hp.snapshot_proxies = false;  // the fitted hands are drawn instead
    s->haptic_ = std::make_unique<HapticSide>(drive != nullptr ? *drive : rig.device(),
                                              rig.device_config(), *scene.world,
                                              scene.params.coupling, hp);
    CubeMonitor* monitor = scene.monitor.get();
    s->haptic_->set_before_step([monitor](physics::World& w) { monitor->before_step(w); });
  }
  // --- the frame side ---
  auto pipe_r = pipeline::FramePipeline::create(context, s->camera_, models, params.pipeline);
  if (!pipe_r) throw SpidarError(pipe_r.error().message);
  s->pipe_ = std::move(pipe_r).value();
  s->alt_params_ = pipeline::comparison_params(params.pipeline);
  if (params.compare && !params.defer_compare) {
    auto alt_r = pipeline::FramePipeline::create(context, s->camera_, models, s->alt_params_);
    if (!alt_r) throw SpidarError(alt_r.error().message);
    s->alt_ = std::move(alt_r).value();
  }
  s->servo_buf_.resize(1000);
  return s;
}

Session::~Session() { stop_threads(); }

pipeline::WarmUpFrame Session::warm_up_frame() const {
  pipeline::WarmUpFrame w;
  const auto rgb = sim::SyntheticCameraParams{}.screen_rgb;
  const vision::Intrinsics& k = camera_.intrinsics();
  w.bgr = cv::Mat(k.height, k.width, CV_8UC3, cv::Scalar(255.0 * rgb[2], 255.0 * rgb[1], 255.0 * rgb[0]));
  std::vector<Vec3> goals(8);
  scene_.task->goals(0.0, goals);
  w.fingertips.finger_count = 8;
  for (int f = 0; f < 8; ++f) w.fingertips.p_W[f] = {goals[f].x(), goals[f].y(), goals[f].z()};
  scene_.world->snapshot(w.scene, false);
  return w;
}

void Session::warm_up() {
  // A blank blue screen with the fingertips where the script starts; both fits are then reset.
  const pipeline::WarmUpFrame w = warm_up_frame();
  // The main pipeline into the pool's results, all held at once (SessionParams::warm_results).
  std::vector<std::shared_ptr<pipeline::FrameResult>> held;
  std::vector<pipeline::FrameResult*> into;
  for (int k = 0; k < params_.warm_results; ++k) {
    held.push_back(results_.take());
    into.push_back(held.back().get());
  }
  if (auto st = pipeline::warm_up(*pipe_, w, into); !st) throw SpidarError(st.error().message);
  if (alt_)
    if (auto st = pipeline::warm_up(*alt_, w); !st) throw SpidarError(st.error().message);
  ++warm_ups_;
}

void Session::start() {
  if (started_) return;
  // Whatever takes time on a first use happens before the clock starts (the haptic side's open):
  // the pipelines' warm-up, the sinks' start (the output thread's GL contexts and their warm-ups)
  // and the camera's (its first frame). After the clock starts the camera's exposures run, and
  // any of this there would skip or drop the first frames.
  if (params_.warm_up) warm_up();
  started_ = true;
  // Any failure from here stops what started (the haptic side, the camera) and re-throws.
  try {
    for (FrameSink* k : sinks_) k->on_start();
    if (auto st = rig_.camera().prepare(); !st) throw SpidarError("camera: " + st.error().message);
    // The scene as it starts, for frames the camera delivers before the physics thread's first
    // snapshot (the first exposure is 5 ms after the start, sim::CameraThreadParams).
    scene_.world->snapshot(snapshot_, false);
    if (haptic_) {
      haptic_->start();  // throws with the haptic side stopped again
      t_start_ns_ = haptic_->t_open_ns();
    } else {
      t_start_ns_ = core::monotonic_ns();  // snapshot_: the shapes the recorded poses apply to
    }
    if (auto st = rig_.camera().start(t_start_ns_); !st) throw SpidarError("camera: " + st.error().message);
  } catch (...) {
    stop_threads();
    throw;
  }
}

bool Session::servo_running() const { return !haptic_ || haptic_->loop().running(); }

bool Session::running() const {
  return started_ && !threads_stopped_ && servo_running() && !rig_.camera().ended();
}

double Session::seconds() const {
  return started_ ? core::ns_to_s(core::monotonic_ns() - t_start_ns_) : 0.0;
}

device::ServoLoop& Session::servo() {
  if (!haptic_) throw SpidarError(rig_.name() + ": a recording played back has no servo loop");
  return haptic_->loop();
}

const device::ServoLoop& Session::servo() const {
  if (!haptic_) throw SpidarError(rig_.name() + ": a recording played back has no servo loop");
  return haptic_->loop();
}

sim::PhysicsThreadStats Session::physics_stats() const {
  return haptic_ ? haptic_->physics().stats() : sim::PhysicsThreadStats{};
}

bool Session::take_inputs(std::int64_t t_exposure_ns, ServoTiming* servo) {
  if (!haptic_) {
    if (frame_.measured == nullptr) throw SpidarError(rig_.name() + ": a frame without its recorded fingertips");
    measured_ = *frame_.measured;
    if (frame_.scene_poses != nullptr && !frame_.scene_poses->empty()) {
      if (frame_.scene_poses->size() != snapshot_.shapes.size())
        throw SpidarError(rig_.name() + ": " + std::to_string(frame_.scene_poses->size()) +
                          " scene poses for a scene of " + std::to_string(snapshot_.shapes.size()) + " shapes");
      for (std::size_t k = 0; k < snapshot_.shapes.size(); ++k) snapshot_.shapes[k].X_WS = (*frame_.scene_poses)[k];
    }
    return true;
  }
  // Back to the exposure and to the last frame's newest sample (the servo timing since then).
  const std::int64_t back_to = last_servo_t_ > 0 ? std::min(t_exposure_ns, last_servo_t_) : 0;
  const device::ServoLoop& loop = haptic_->loop();
  const std::size_t ns = device::read_back_to(
      [&loop](device::FingertipSample* out, std::size_t max) { return loop.newest_samples(out, max); }, back_to,
      std::span(servo_buf_));
  const auto measured = device::interpolate_samples({servo_buf_.data(), ns}, t_exposure_ns);
  if (!measured) return false;
  measured_ = *measured;
  // The newest the physics thread published; before its first, the scene as it started.
  if (haptic_->physics().snapshots().update()) snapshot_ = haptic_->physics().snapshots().front();
  *servo = servo_timing_since({servo_buf_.data(), ns}, params_.servo.rate_hz, &last_servo_t_);
  return true;
}

std::uint64_t Session::camera_frames() const { return rig_.camera().delivered(); }

void Session::wait_for_frame(std::int64_t deadline_ns) {
  if (!started_ || threads_stopped_) {
    core::sleep_until_ns(std::min(deadline_ns, core::monotonic_ns() + kFrameWaitNs));
    return;
  }
  rig_.camera().wait_for_frame(deadline_ns);
}

Session::Step Session::step() {
  if (!started_ || threads_stopped_) return Step::kNoFrame;
  try {
    if (!rig_.camera().take(&frame_)) return Step::kNoFrame;
    const vision::Intrinsics& k = camera_.intrinsics();  // the lens's image size too
    if (frame_.bgr.cols != k.width || frame_.bgr.rows != k.height)
      throw SpidarError("camera: a frame of " + std::to_string(frame_.bgr.cols) + "x" +
                        std::to_string(frame_.bgr.rows) + " px, expected " + std::to_string(k.width) +
                        "x" + std::to_string(k.height));
    const std::int64_t t_exp = frame_.t_exposure_ns;
    const double t_s = frame_.filmed != nullptr  ? frame_.filmed->t_script_s
                       : frame_.measured != nullptr ? frame_.t_recorded_s
                                                    : core::ns_to_s(t_exp - t_start_ns_);
    if ((params_.seconds > 0 && t_s > params_.seconds) ||
        (params_.end_with_script && scene_.task->finished(t_s))) {
      // The frame that ends the run is not dropped (SessionSummary::camera_frames).
      if (!delivered_before_end_) delivered_before_end_ = rig_.camera().delivered() - 1;
      return Step::kPastEnd;
    }
    t_last_s_ = t_s;
    // The frame thread's context (a sink on this thread may have made its own current).
    if (auto st = context_.make_current(); !st) throw SpidarError("frame thread: " + st.error().message);
    FrameEvent e;
    if (!take_inputs(t_exp, &e.servo)) return Step::kSkipped;  // a stall: no servo samples around it

    e.cold_start = !pipe_->has_previous();
    result_ = results_.take();  // one no sink still holds (its images are reused, not reallocated)
    // Through a lens: the pinhole camera's image (camera_), which the pipelines and sinks see.
    if (lens_) lens_->undistort(frame_.bgr, &undistorted_);
    const cv::Mat& image = lens_ ? undistorted_ : frame_.bgr;
    if (auto st = pipe_->process(image, measured_, snapshot_, result_.get()); !st)
      throw SpidarError(st.error().message);
    e.t_done_ns = core::monotonic_ns();
    // The comparison registration runs every frame (it must track), its rendering every
    // compare_every-th frame (a sample of the run; it costs as much as the main pipeline).
    if (params_.compare) {
      const bool render = frames_ % static_cast<std::uint64_t>(std::max(1, params_.compare_every)) == 0;
      if (!alt_) {
        e.compare_pending = render ? PendingComparison::kFitAndPicture : PendingComparison::kFit;
      } else {
        if (auto st = pipeline::process_comparison(*alt_, *result_, image, measured_, snapshot_, render,
                                                   &alt_result_);
            !st)
          throw SpidarError(st.error().message);
        if (render) e.compared = &alt_result_;
        e.compare_ms = core::ns_to_s(core::monotonic_ns() - e.t_done_ns) * 1e3;
      }
    }
    if (scene_.monitor) e.cube = scene_.monitor->status().read();
    e.index = frames_;
    e.t_exposure_ns = t_exp;
    e.t_s = t_s;
    e.bgr = &image;
    e.sensor_bgr = &frame_.bgr;
    e.measured = &measured_;
    e.scene = &snapshot_;
    e.result = result_.get();
    e.result_hold = result_;
    e.filmed = frame_.filmed;
    e.filmed_hold = frame_.filmed != nullptr ? frame_.filmed_hold : nullptr;
    for (FrameSink* sink : sinks_) sink->on_frame(e);
    ++frames_;
    return Step::kFrame;
  } catch (...) {
    stop_threads();
    throw;
  }
}

SessionSummary Session::run(const std::function<std::optional<std::string>()>& interrupted) {
  start();
  // After start(): the threads it made keep their own scheduling, not this one's. The caller's
  // is given back when run() returns (or throws).
  struct RestoreScheduling {
    core::ThreadScheduling was = core::current_scheduling();
    bool done = false;
    void now() {
      if (!std::exchange(done, true)) (void)core::apply_scheduling(was);
    }
    ~RestoreScheduling() { now(); }
  } restore;
  if (params_.frame_nice != 0) (void)core::set_nice(params_.frame_nice);  // best effort
  if (params_.frame_fifo_priority > 0) {
    const Status rt = core::set_fifo_priority(params_.frame_fifo_priority);
    frame_realtime_ = rt.ok();
    if (!rt.ok()) {
      // The nice value it has (frame_nice may have been refused too).
      spdlog::warn("session: the frame thread runs at nice {} instead of SCHED_FIFO {} ({}); on a busy "
                   "machine expect more latency and dropped frames",
                   core::current_scheduling().nice, params_.frame_fifo_priority, rt.error().message);
    }
  }
  std::string ended_by = "completed";
  while (servo_running()) {
    if (interrupted) {
      if (auto why = interrupted()) {
        ended_by = *why;
        break;
      }
    }
    if (rig_.camera().ended()) {
      ended_by = "camera ended";
      break;
    }
    const Step st = step();
    if (st == Step::kPastEnd) break;
    if (st == Step::kNoFrame) {  // wait for the next frame (woken when it is published)
      if (params_.seconds > 0 && seconds() > params_.seconds + 1.0) break;
      wait_for_frame(core::monotonic_ns() + kFrameWaitNs);
    }
  }
  restore.now();  // the sinks' on_end (reports, plots) at the caller's scheduling
  return stop(ended_by);
}

void Session::stop_threads() {
  if (threads_stopped_) return;
  threads_stopped_ = true;
  rig_.camera().stop();
  if (haptic_) haptic_->stop();
}

SessionSummary Session::stop(const std::string& ended_by) {
  if (summary_) return *summary_;
  const double wall_s = seconds();
  std::vector<core::ThreadCpu> thread_cpu = core::thread_cpu_by_name();  // while they all still run
  stop_threads();
  SessionSummary s;
  s.thread_cpu = std::move(thread_cpu);
  s.ended_by = ended_by;
  s.wall_s = wall_s;
  s.t_last_s = t_last_s_;
  s.frames = frames_;
  s.camera_frames = delivered_before_end_.value_or(rig_.camera().delivered());
  s.camera_skipped = rig_.camera().skipped();
  if (haptic_) {
    s.servo = haptic_->loop().stats();
    s.physics = haptic_->physics().stats();
  }
  s.camera_error = rig_.camera().error();
  s.frame_realtime = frame_realtime_;
  summary_ = s;
  for (FrameSink* k : sinks_) k->on_end(s);
  return s;
}

}  // namespace spidar::session
