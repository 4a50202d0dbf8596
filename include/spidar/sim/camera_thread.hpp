#pragma once
/// The simulated rig's camera as a camera is to a frame thread: its own thread films the user's
/// real hands at the camera rate (with its own headless GL context) and hands over each frame
/// with its exposure time and its ground truth; the frame thread takes the newest frame whenever
/// it is ready for one, so a slow frame thread drops frames, it never slows the camera.
///
/// Per frame: the true fingertip caps at the exposure time (the simulated device's ground truth,
/// interpolated), the user's hand posture for them (UserHands), then the synthetic camera.
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>

#include "spidar/core/done_flag.hpp"
#include "spidar/core/result.hpp"
#include "spidar/core/recycling_pool.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/sim/user_hands.hpp"

namespace spidar::sim {

struct FilmedFrame {
  std::uint64_t index = 0;         ///< frame number since start (gaps: frames not taken)
  std::int64_t t_exposure_ns = 0;  ///< host monotonic time of the exposure [ns]
  double t_script_s = 0;           ///< the scenario's time at the exposure [s]
  /// The image (frame.bgr, frame.toward_elbow_W) is complete when the frame is published; its
  /// ground-truth images (frame.mask, hand_index, hand_only, depth, hand_id) only once truth_images is
  /// done: the camera thread reads them after publishing, off the frame's latency. Their readers
  /// wait first (wait_for_truth_images). Done by default: a frame made otherwise is complete.
  SyntheticFrame frame;
  core::DoneFlag truth_images{true};
  std::array<hand::HandParams, 2> truth;  ///< the user's hands at the exposure
  std::array<double, 2> cap_residual_m{};  ///< UserHands::cap_residual_m
  double film_ms = 0;              ///< cost of posing and filming the image, to its publication [ms]
  double truth_images_ms = 0;      ///< then reading its ground-truth images [ms] (once they are done)

  /// Blocks until the ground-truth images are written; then `frame` is complete.
  const SyntheticFrame& wait_for_truth_images() const {
    truth_images.wait();
    return frame;
  }
};

/// A deep copy, once `from`'s ground-truth images are done (the images copied into `to`'s
/// buffers when they fit, so a reused `to` allocates nothing). A FilmedFrame taken from
/// CameraThread::frame() is only valid until the next take(); CameraThread::shared() keeps one
/// for longer without a copy.
void copy_filmed_frame(const FilmedFrame& from, FilmedFrame* to);

/// What a ground-truth source had at a time.
enum class Truth {
  kNone,   ///< no fingertips yet (`out` untouched)
  kHeld,   ///< the newest sample, from before the time (the one after it has not come yet)
  kExact,  ///< samples on both sides of the time, interpolated (or an exact source)
};

/// Fills `out` with the true fingertip caps at t_ns (8 of them) and says how they were had.
using TruthAt = std::function<Truth(std::int64_t t_ns, std::span<Vec3> out)>;

struct CameraThreadParams {
  double fps = 30.0;
  std::int64_t t0_ns = 0;        ///< script time 0 (host monotonic) [ns]: start() only (prepare() + begin())
  /// The first exposure this long after t0 [ns], the next ones a period apart. The simulated
  /// device's first sample comes just after t0 (the session's clock starts when it opens), so an
  /// exposure at t0 itself has no ground truth and was always skipped (a dropped first frame in
  /// every run). [0, 1e9].
  std::int64_t first_exposure_ns = 5'000'000;
  /// The sensor's readout [ns]: a frame is published no earlier than this after its exposure.
  std::int64_t readout_ns = 2'000'000;
  /// The longest wait after the exposure for its exact ground truth [ns]: the camera asks from
  /// the exposure on, every truth_poll_ns, until the simulated device's fingertip sample after
  /// the exposure has come (Truth::kExact: on average half a servo period later, at most one and
  /// its delay); past this wait it films with the newest sample held (Truth::kHeld). The posing
  /// and filming (the simulation's own cost, which a real sensor does not have) run during the
  /// readout, not after it. [0, 1e9].
  std::int64_t truth_wait_ns = 1'200'000;
  /// How often the camera asks for the exact ground truth during truth_wait_ns [ns]. [1e3, 1e9].
  std::int64_t truth_poll_ns = 100'000;
  /// The thread's niceness (core::set_nice, best effort): the simulated camera is hardware, which
  /// films at its rate whatever the host does, so it goes before the frame thread and the outputs
  /// that share the CPU with it. Needs CAP_SYS_NICE below 0; without it, a normal share.
  int nice = -10;
  /// The thread's SCHED_FIFO priority (0: its niceness only; best effort, the niceness where it is
  /// refused): above the frame thread's 20 and the physics' 25, below the servo's 80, so that a
  /// busy machine does not delay the exposures' films (session::SessionParams::frame_fifo_priority
  /// for the figures). 0..99.
  int fifo_priority = 30;
  /// Frames filmed into the pool before the clock starts (prepare), all held at once and then
  /// let go: the frames the session holds at a time (the frame thread's and the output thread's,
  /// 6 in the demo) have their images allocated and touched before the first exposure instead of
  /// during the first ones (a new frame's page faults cost 10–20 ms on this VM). 0..64.
  int warm_frames = 6;
};

class CameraThread {
 public:
  /// Starts the thread; returns once its GL context and camera exist and it has filmed one frame
  /// (at the task's first nominal poses, thrown away: the GL driver compiles its shaders at the
  /// first draw), or with the error why not. It films nothing until begin().
  static Result<std::unique_ptr<CameraThread>> prepare(const vision::Camera& camera,
                                                       const std::array<hand::HandModel, 2>& truth,
                                                       const SyntheticCameraParams& film_params,
                                                       const RubiksTask& task, TruthAt truth_at,
                                                       const CameraThreadParams& params);
  /// Starts the exposures: the first at `t0_ns` (script time 0, host monotonic) [ns]; later calls
  /// do nothing.
  void begin(std::int64_t t0_ns);
  /// prepare(), then begin(params.t0_ns).
  static Result<std::unique_ptr<CameraThread>> start(const vision::Camera& camera,
                                                     const std::array<hand::HandModel, 2>& truth,
                                                     const SyntheticCameraParams& film_params,
                                                     const RubiksTask& task, TruthAt truth_at,
                                                     const CameraThreadParams& params);
  ~CameraThread();
  CameraThread(const CameraThread&) = delete;
  CameraThread& operator=(const CameraThread&) = delete;

  /// The newest frame if one arrived since the last call (then `frame()` holds it). Frames filmed
  /// in between and never taken go back to the pool.
  bool take();
  /// Blocks until a frame is ready to take(), the thread stops, or `deadline_ns` [ns, monotonic]
  /// passes; true if a frame is ready.
  bool wait_for_frame(std::int64_t deadline_ns);
  /// The frame the last successful take() gave (an empty frame before the first).
  const FilmedFrame& frame() const { return current_ ? *current_ : empty_; }
  /// The same frame, shared: the camera films into other frames (core::RecyclingPool) while anyone
  /// holds it, so a holder may read it after the next take() (null before the first take()).
  std::shared_ptr<const FilmedFrame> shared() const { return current_; }
  /// Frames filmed so far.
  std::uint64_t filmed() const { return filmed_.load(std::memory_order_acquire); }
  /// Exposures this thread let pass without filming them: because it was late (on a busy machine
  /// the simulated camera itself falls behind its rate; a real camera would not), or because the
  /// ground truth had no fingertips yet at that time. Every exposure is filmed or skipped, so the
  /// index of a frame is the count of both before it.
  std::uint64_t skipped() const { return skipped_.load(std::memory_order_acquire); }
  /// The error that stopped the thread, if any (read after stop()).
  const std::string& error() const { return error_; }
  void stop();

 private:
  CameraThread() = default;
  void run(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth,
           const SyntheticCameraParams& film_params, const RubiksTask& task,
           std::function<void(Status)> ready);

  CameraThreadParams params_;
  TruthAt truth_at_;
  /// Frames to film into; the newest filmed one not yet taken (under newest_mutex_); the one the
  /// frame thread took last (its thread only).
  core::RecyclingPool<FilmedFrame> pool_;
  std::mutex newest_mutex_;
  std::condition_variable arrived_;  ///< a frame published, or the thread ended (newest_mutex_)
  bool ended_ = false;               ///< under newest_mutex_
  std::shared_ptr<FilmedFrame> newest_;
  std::shared_ptr<const FilmedFrame> current_;
  FilmedFrame empty_;
  std::atomic<std::uint64_t> filmed_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<bool> stop_{false};
  /// The exposures' start (begin()), or a stop, releases the prepared thread.
  std::mutex gate_mutex_;
  std::condition_variable gate_;
  std::optional<std::int64_t> t0_ns_;
  std::string error_;
  std::thread thread_;
};

}  // namespace spidar::sim
