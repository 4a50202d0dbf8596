#pragma once
/// One running system (docs/architecture.md, "The flow of one session"): the haptic side — the servo loop
/// driving the rig's device, the physics thread and the bridge between them — and the frame side
/// — camera frames through pipeline::FramePipeline (and optionally a comparison pipeline), with
/// the warm-up before the clock starts, the servo samples interpolated at each exposure, and one
/// FrameEvent per processed frame fanned out to the sinks.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "spidar/core/recycling_pool.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/session/haptic_side.hpp"
#include "spidar/session/rig.hpp"
#include "spidar/session/scene.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/lens_undistortion.hpp"

namespace spidar::session {

struct SessionParams {
  device::ServoConfig servo;            ///< rate, limits, timeouts of the servo loop
  pipeline::FramePipelineParams pipeline;
  /// A second registration with the silhouette term switched the other way, fitted every frame
  /// (it must track) and rendered every `compare_every`-th frame (FrameEvent::compared).
  bool compare = false;
  int compare_every = 5;
  /// The comparison (its fit every frame, its picture every compare_every-th) is left to a sink
  /// on another thread (AsyncSinks::compare): the frame thread only marks each event
  /// (FrameEvent::compare_pending) and spends nothing on a figure nobody sees live.
  bool defer_compare = false;
  /// One blank frame through each pipeline before the clock starts (GL programs, skins and
  /// workspaces cost ~130 ms on the first frame; in the run they would drop the camera's first
  /// frames); the fits are reset after it, so the first real frame is a cold start.
  bool warm_up = true;
  /// With warm_up, the frame results the session's pool holds at a time (the frame thread's and
  /// those the sinks still hold: 4 in the demo) are processed from the warm-up frame too, so their
  /// images exist before the clock starts (a new result's page faults cost 10–30 ms on this VM,
  /// in the first frames). 1..32.
  int warm_results = 4;
  /// Frames past this time (FrameEvent::t_s) end the run [s]; 0: no limit.
  double seconds = 0;
  /// The run also ends once the scene's scripted user is done (sim::RubiksTask::finished).
  bool end_with_script = false;
  /// The physics thread's SCHED_FIFO priority: above the frame thread (20), below the servo loop
  /// (80) and the simulated camera (30), which a real rig's camera, a device, never waits for.
  /// At 60, above the camera, the physics' 1 kHz steps preempted the camera's film on its CPU:
  /// quiet demo, seeds 1–8 interleaved (docs/measurements.md, session 48), film 8.4–12.0 ms and
  /// latency median 17.9–25.2 against 8.2–8.7 and 17.7–19.4 at 25; the physics' late steps, the
  /// stale force cycles and the servo's jitter stayed within their bounds. 1..99.
  int physics_priority = 25;
  /// The frame thread's niceness while run() runs (core::set_nice, best effort: below 0 needs
  /// CAP_SYS_NICE, else a normal share): after the simulated camera (−10, hardware), before the
  /// output thread (10) and other programs (0). Demo, one core busy, seeds 4–7 interleaved: −5
  /// against 0 gave latency median 26.2 against 29.0 ms, p95 50 against 58 ms, dropped 1.9 against
  /// 2.9 %. 0: leave it.
  int frame_nice = -5;
  /// The frame thread's SCHED_FIFO priority while run() runs (0: its niceness only), below the
  /// physics (25) and the servo loop (80), with the simulated camera's 30 above it. Its side
  /// helper follows it (core::SideTask). Where SCHED_FIFO is not permitted the session says so
  /// once and the thread keeps frame_nice. Demo, seeds 1–4 interleaved (docs/measurements.md,
  /// session 48), against frame_nice alone: quiet, latency median 18.2–20.2 against 21.2–24.8 ms;
  /// one core busy, 18.9–24.4 against 27.2–28.7 ms, p95 25–32 against 51–62 ms. 1..99 or 0.
  int frame_fifo_priority = 20;
};

/// Error naming the first SessionParams field out of its range (Session::create throws it).
Status validate(const SessionParams& params);

class Session {
 public:
  /// Builds the servo loop, the physics thread and the pipelines (nothing started; a rig that
  /// plays back gets the pipelines only, `scene` gives the shapes its poses apply to). `context`
  /// must be current on the calling thread (the frame thread) and outlive the session, as must
  /// the rig and the scene. `camera`: the camera's calibration; with lens distortion its frames
  /// are undistorted as they arrive, and the pipelines work with its pinhole camera (camera()).
  /// Throws SpidarError naming the coefficients where the lens cannot be undistorted. `drive`: the device the servo loop drives if not the rig's own (a
  /// wrapper around it, e.g. one that records every cycle). Throws SpidarError saying what failed.
  static std::unique_ptr<Session> create(Rig& rig, Scene& scene, render::Context& context,
                                         const vision::Camera& camera,
                                         const std::array<hand::HandModel, 2>& models,
                                         const SessionParams& params,
                                         device::Device* drive = nullptr);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// Sinks see events in the order they were added; they must outlive the session's run.
  void add_sink(FrameSink& sink) { sinks_.push_back(&sink); }

  /// The warm-up (if asked for), then opens the device and starts physics, servo loop and camera;
  /// the sinks' on_start. Throws SpidarError (the threads stopped) if any of them fails.
  void start();

  enum class Step {
    kNoFrame,  ///< no new camera frame
    kSkipped,  ///< a frame without servo samples around its exposure (a stall): not processed
    kFrame,    ///< a frame processed and fanned out to the sinks
    kPastEnd,  ///< a frame past SessionParams::seconds or the script's end: the run is over
  };
  /// Processes the newest camera frame if one arrived since the last call. An exception (the
  /// pipeline or a sink) stops the threads (device in its safe state) and propagates.
  Step step();
  /// Blocks until the camera may have a frame for step(), or `deadline_ns` [ns, monotonic]
  /// (FrameSource::wait_for_frame): the frame thread wakes when the frame is published rather
  /// than at its next poll.
  void wait_for_frame(std::int64_t deadline_ns);

  /// Steps until the servo loop stops (a fault), the camera ends, a frame is past `seconds`, no
  /// frame came for `seconds` + 1 s, or `interrupted()` names a reason (e.g. "SIGINT"); then
  /// stop(). Returns the summary.
  SessionSummary run(const std::function<std::optional<std::string>()>& interrupted = {});

  /// Stops the camera, the servo loop (device in its safe state), physics, closes the device and
  /// calls the sinks' on_end. Idempotent: later calls return the first summary.
  SessionSummary stop(const std::string& ended_by = "stopped");

  /// False once stopped, or the servo loop ended (a fault), or the camera ended or failed.
  bool running() const;
  bool started() const { return started_; }
  /// Seconds since start().
  double seconds() const;
  std::int64_t t_start_ns() const { return t_start_ns_; }
  std::uint64_t frames() const { return frames_; }
  /// Warm-ups done: 1 after start() with SessionParams::warm_up, else 0.
  int warm_ups() const { return warm_ups_; }
  /// The frame the warm-up processes (the blue screen without hands, the fingertips where the
  /// task begins, the scene as it starts): for pipelines of the session's sinks to warm up with
  /// too (AsyncSinks::compare).
  pipeline::WarmUpFrame warm_up_frame() const;
  std::uint64_t camera_frames() const;

  /// The camera the pipelines work in: the calibration given, or, where it has lens distortion,
  /// the pinhole camera its frames are undistorted into (vision::LensUndistortion).
  const vision::Camera& camera() const { return camera_; }
  Rig& rig() { return rig_; }
  Scene& scene() { return scene_; }
  /// The servo loop; SpidarError for a rig that plays back (it has none).
  device::ServoLoop& servo();
  const device::ServoLoop& servo() const;
  sim::PhysicsThreadStats physics_stats() const;
  pipeline::FramePipeline& pipeline() { return *pipe_; }
  /// The comparison pipeline's params (pipeline::comparison_params of the main one's); null
  /// without a comparison.
  const pipeline::FramePipelineParams* comparison_params() const {
    return params_.compare ? &alt_params_ : nullptr;
  }
  const SessionParams& params() const { return params_; }

 private:
  Session(Rig& rig, Scene& scene, render::Context& context, const SessionParams& params);
  void warm_up();
  void stop_threads();
  bool servo_running() const;
  /// Where the frame's measurement and scene come from: the servo loop and physics, or the
  /// recording the frame came from. False: no servo samples around the exposure (a stall).
  bool take_inputs(std::int64_t t_exposure_ns, ServoTiming* servo);

  Rig& rig_;
  Scene& scene_;
  render::Context& context_;
  SessionParams params_;
  vision::Camera camera_;  ///< the pipelines' (pinhole) camera
  std::optional<vision::LensUndistortion> lens_;  ///< the calibration's lens, if it has distortion
  cv::Mat undistorted_;  ///< the frame undistorted (lens_ only)
  std::unique_ptr<HapticSide> haptic_;
  std::unique_ptr<pipeline::FramePipeline> pipe_, alt_;  // alt_: a comparison made here
  pipeline::FramePipelineParams alt_params_;
  std::vector<FrameSink*> sinks_;

  bool started_ = false, threads_stopped_ = false;
  std::optional<SessionSummary> summary_;
  std::uint64_t frames_ = 0;
  int warm_ups_ = 0;
  double t_last_s_ = 0;
  std::int64_t last_servo_t_ = 0;
  std::int64_t t_start_ns_ = 0;
  std::vector<device::FingertipSample> servo_buf_;
  CameraFrame frame_;
  SceneSnapshot snapshot_;
  device::FingertipSample measured_;
  /// The main fit's results: each frame's taken from the pool and shared with the sinks
  /// (FrameEvent::result_hold), so that the output thread reads it while the next is filled,
  /// without a copy of its eleven images per frame.
  core::RecyclingPool<pipeline::FrameResult> results_;
  /// The camera's delivered count before the frame past the end (Step::kPastEnd), once one came.
  std::optional<std::uint64_t> delivered_before_end_;
  bool frame_realtime_ = false;  ///< SessionParams::frame_fifo_priority granted in run()
  std::shared_ptr<pipeline::FrameResult> result_;
  pipeline::FrameResult alt_result_;
};

}  // namespace spidar::session
