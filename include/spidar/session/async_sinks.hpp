#pragma once
/// Sinks off the frame thread's critical path: the ground-truth scorer, the video and keyframe
/// writers and the progress line cost as much as the pipeline itself, and the next camera frame
/// would wait for them. AsyncSinks copies each event into one of a few slots (the camera image,
/// the measurement, the scene, both fits with their composites, the ground truth) and runs its
/// sinks on its own thread, the output thread, in order, while the frame thread goes on.
///
/// No frame is skipped: when every slot is taken (the sinks are slower than the pipeline), on_frame
/// waits for one, and the waits are counted. The sinks' on_start, on_frame and on_end all run on
/// the output thread, so a sink may make its own GL context there (the scorer's model ceiling).
/// An exception from a sink is re-thrown on the frame thread at the next on_frame or at on_end
/// (the session then stops); the sinks after it do not see that frame.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "spidar/render/context.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

class AsyncSinks final : public FrameSink {
 public:
  /// `sinks` must outlive this group; `slots` ≥ 1 frames may wait for (or be in) the sinks.
  /// `nice` (−20..19, best effort): the output thread's niceness (core::set_nice).
  explicit AsyncSinks(std::vector<FrameSink*> sinks, int slots = 3, int nice = 0);
  /// Stops the output thread (the frames still queued are not delivered, no on_end).
  ~AsyncSinks() override;
  AsyncSinks(const AsyncSinks&) = delete;
  AsyncSinks& operator=(const AsyncSinks&) = delete;

  /// Makes the comparisons the session left pending (FrameEvent::compare_pending,
  /// SessionParams::defer_compare) on the output thread, before the sinks see the frame: every
  /// frame's fit (the comparison tracks) with the sizes the main fit used, and the picture where
  /// asked (then FrameEvent::compared points at it), with a FramePipeline of the comparison's
  /// params (pipeline::comparison_params of `main`, the main pipeline's) and a headless GL
  /// context of its own (created in on_start there); it reuses the main result's matte. Call
  /// before on_start. With `warm_up` (Session::warm_up_frame), the comparison's pipeline processes
  /// it in on_start (pipeline::warm_up): its first frame in the run is not the one that compiles
  /// the GL programs (160 ms, which held the frame thread's first frames).
  void compare(const vision::Camera& camera, const std::array<hand::HandModel, 2>& models,
               const pipeline::FramePipelineParams& main,
               std::optional<pipeline::WarmUpFrame> warm_up = std::nullopt);
  /// Composes the other mode's composite (FrameResult::other, other_alpha: the comparison of the
  /// two compositors) of every frame's result and comparison that lacks it, on the output thread
  /// before the sinks see the frame: for a session whose pipelines leave it out
  /// (FramePipelineParams::other_composite off), so that the frame thread makes only the
  /// composite shown. `main`: the main pipeline's compositor. Call before on_start.
  void compose_others(const render::CompositorParams& main);
  /// Starts the output thread and waits for the sinks' on_start there (re-throws its exception).
  void on_start() override;
  /// Copies the event into a free slot (waiting for one if none is) and queues it. A result or a
  /// filmed frame the event shares (FrameEvent::result_hold, filmed_hold) is held there instead of
  /// copied (the filmed frame's image too, when the event's image is it), until the sinks are done.
  void on_frame(const FrameEvent& e) override;
  /// Delivers every queued frame, then the sinks' on_end, on the output thread; joins it.
  void on_end(const SessionSummary& s) override;

  /// Times on_frame found every slot taken and waited, and for how long in all [ms].
  std::uint64_t waits() const;
  double waited_ms() const;

 private:
  struct Slot {
    FrameEvent e;  ///< points into this slot's copies
    cv::Mat bgr, sensor_bgr;
    device::FingertipSample measured;
    SceneSnapshot scene;
    pipeline::FrameResult result, compared;
    sim::FilmedFrame filmed;
    /// A held result with the other composite added (compose_others): its images shared with
    /// the held one, the other composite's in `other` and `other_alpha` (reused frame to frame).
    pipeline::FrameResult shown;
    cv::Mat other, other_alpha;
  };
  void run();
  void copy_into(const FrameEvent& from, Slot& to) const;
  void rethrow_if_failed();

  /// The comparison (compare), made on the output thread.
  struct Comparison {
    vision::Camera camera;
    std::array<hand::HandModel, 2> models;
    pipeline::FramePipelineParams params;
    std::unique_ptr<render::Context> context;
    std::unique_ptr<pipeline::FramePipeline> pipeline;
    pipeline::FrameResult result;  ///< the newest frame's (the sinks read it during on_frame)
    std::optional<pipeline::WarmUpFrame> warm_up;
  };
  void start_comparison();
  void make_comparison(Slot& slot);
  void compose_other(Slot& slot);

  std::vector<FrameSink*> sinks_;
  std::unique_ptr<Comparison> comparison_;
  std::optional<render::Compositor> other_;  ///< compose_others: in the main one's other mode
  std::vector<Slot> slots_;
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::size_t> free_;    ///< slots the frame thread may fill
  std::deque<std::size_t> queued_;   ///< slots waiting for the sinks, oldest first
  bool started_ = false, ending_ = false, quit_ = false;
  std::optional<SessionSummary> summary_;
  std::exception_ptr error_;
  int nice_ = 0;
  std::uint64_t waits_ = 0;
  double waited_ms_ = 0;
};

}  // namespace spidar::session
