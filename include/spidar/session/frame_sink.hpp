#pragma once
/// What a session hands to its sinks: one event per processed camera frame, fanned out in the
/// order the sinks were added (the recorder, the GUI's view model, the ground-truth scorer, the
/// video and keyframe writers, the progress bar), and a summary when the session ends.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "spidar/core/scene_snapshot.hpp"
#include "spidar/core/thread_name.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/servo_timing.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/sim/haptic_bridge.hpp"

namespace spidar::session {

/// A comparison the session left to be made elsewhere (SessionParams::defer_compare).
enum class PendingComparison {
  kNone,
  kFit,            ///< fit this frame (the comparison tracks every frame)
  kFitAndPicture,  ///< fit it and render its picture (a compared frame)
};

/// One processed frame. Everything it refers to is valid during on_frame only (clone to keep).
struct FrameEvent {
  std::uint64_t index = 0;          ///< processed frames before this one
  std::int64_t t_exposure_ns = 0;   ///< host monotonic time of the exposure [ns]
  std::int64_t t_done_ns = 0;       ///< when the main pipeline finished [ns, monotonic]
  /// Time of the exposure [s]: the script's time on the simulated rig, else since the session
  /// started.
  double t_s = 0;
  /// The camera image the pipelines saw: undistorted, where the camera's calibration has a lens
  /// (Session::camera(), vision::LensUndistortion).
  const cv::Mat* bgr = nullptr;
  /// The frame as the camera delivered it, through its lens (what a recording keeps, so that its
  /// replay undistorts it as the session did); the same as `bgr` without a lens.
  const cv::Mat* sensor_bgr = nullptr;
  const device::FingertipSample* measured = nullptr;  ///< servo samples interpolated at exposure
  const SceneSnapshot* scene = nullptr;            ///< the virtual world the frame was rendered with
  const pipeline::FrameResult* result = nullptr;   ///< the main pipeline's fit and composite
  /// The same result, shared (a session hands out each frame's from a core::RecyclingPool and
  /// fills another next frame): a sink that keeps it past on_frame holds this instead of copying
  /// it, and nobody overwrites it while it is held. Null where the result is not shared (copy it).
  std::shared_ptr<const pipeline::FrameResult> result_hold;
  /// The comparison pipeline (silhouette term switched the other way), rendered this frame;
  /// null when the session has no comparison or skipped its rendering in this frame.
  const pipeline::FrameResult* compared = nullptr;
  /// The comparison left to another thread (SessionParams::defer_compare): AsyncSinks::compare
  /// fits it (and pictures it, then setting `compared`) before its sinks see the frame.
  PendingComparison compare_pending = PendingComparison::kNone;
  /// What the synthetic camera filmed (ground truth); null for real cameras.
  const sim::FilmedFrame* filmed = nullptr;
  /// The same filmed frame, shared (the synthetic camera films into others while it is held): a
  /// sink that keeps it past on_frame holds this instead of copying it; null: copy it.
  std::shared_ptr<const sim::FilmedFrame> filmed_hold;
  ServoTiming servo;  ///< the servo loop's rate and jitter since the previous frame
  bool cold_start = false;  ///< the main fit started from the rest pose, not the previous frame
  /// The scene's cube when the frame was processed (its monitor's newest status); empty without
  /// a cube or before the physics thread published one.
  std::optional<CubeStatus> cube;
  double compare_ms = 0;  ///< the comparison pipeline's cost in this frame [ms] (0 without one)
};

/// How a session ended.
struct SessionSummary {
  std::string ended_by = "completed";  ///< completed | SIGINT | SIGTERM | stopped | camera ended
  double wall_s = 0;                   ///< since the device was opened [s]
  double t_last_s = 0;                 ///< FrameEvent::t_s of the last frame before the end [s]
  std::uint64_t frames = 0;            ///< processed
  /// Delivered by the camera (processed or dropped) up to the frame that ended the run: a frame
  /// past SessionParams::seconds or the script's end, which ends it, is not counted, nor any
  /// filmed after it.
  std::uint64_t camera_frames = 0;
  std::uint64_t camera_skipped = 0;    ///< exposures the camera itself did not deliver (FrameSource::skipped)
  device::ServoStats servo;
  sim::PhysicsThreadStats physics;
  std::string camera_error;            ///< why the camera stopped, if it failed
  /// The frame thread ran at SCHED_FIFO (SessionParams::frame_fifo_priority was granted).
  bool frame_realtime = false;
  /// CPU time by thread name just before the session's threads stopped (core::thread_cpu_by_name:
  /// the frame thread under the program's name, spidar-servo, spidar-physics, spidar-camera, ...).
  std::vector<core::ThreadCpu> thread_cpu;
};

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// Once, after the servo loop and physics started and before the camera (the first frame).
  virtual void on_start() {}
  /// Every processed frame, in order, on the frame thread. An exception stops the session (its
  /// threads are stopped, the device left in its safe state) and propagates to the caller.
  virtual void on_frame(const FrameEvent& e) = 0;
  /// Once, after the threads stopped.
  virtual void on_end(const SessionSummary& /*summary*/) {}
};

/// A sink made of a function (a progress line, presenting in a window).
class FunctionSink final : public FrameSink {
 public:
  explicit FunctionSink(std::function<void(const FrameEvent&)> on_frame,
                        std::function<void(const SessionSummary&)> on_end = {})
      : on_frame_(std::move(on_frame)), on_end_(std::move(on_end)) {}
  void on_frame(const FrameEvent& e) override { on_frame_(e); }
  void on_end(const SessionSummary& s) override {
    if (on_end_) on_end_(s);
  }

 private:
  std::function<void(const FrameEvent&)> on_frame_;
  std::function<void(const SessionSummary&)> on_end_;
};

/// Several sinks as one, timing what they cost per frame (the demo's output time).
class SinkGroup final : public FrameSink {
 public:
  explicit SinkGroup(std::vector<FrameSink*> sinks) : sinks_(std::move(sinks)) {}
  void on_start() override;
  void on_frame(const FrameEvent& e) override;
  void on_end(const SessionSummary& s) override;
  /// Wall time the group's sinks took for the last frame [ms].
  double last_ms() const { return last_ms_; }

 private:
  std::vector<FrameSink*> sinks_;
  double last_ms_ = 0;
};

}  // namespace spidar::session
