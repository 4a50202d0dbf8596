#pragma once
/// Where a session's camera frames come from: the synthetic camera filming the simulated user
/// (scripted or interactive), a real camera (V4L2 device) or a video file. Each source runs its
/// own thread; the frame thread takes the newest frame (older ones are dropped, as a camera's are).
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/capture.hpp"

namespace spidar::session {

class InteractiveHands;

/// One camera frame as the frame thread receives it.
struct CameraFrame {
  cv::Mat bgr;                     ///< the image (valid until the next take(); clone to keep it)
  std::int64_t t_exposure_ns = 0;  ///< host monotonic time of the exposure [ns]
  /// What the synthetic camera filmed (true hand poses, script time, ...); null for real cameras.
  const sim::FilmedFrame* filmed = nullptr;
  /// The same filmed frame, shared (sim::CameraThread::shared): valid, and not overwritten, for as
  /// long as it is held; null where the source does not share its frames.
  std::shared_ptr<const sim::FilmedFrame> filmed_hold;
  /// A recording's frame (Rig::plays_back): the fingertip sample its registration used, the scene
  /// poses it was rendered with (empty: the scene has no shapes) and its time since the
  /// recording's first frame [s]; null for live cameras.
  const device::FingertipSample* measured = nullptr;
  const std::vector<Pose>* scene_poses = nullptr;
  double t_recorded_s = 0;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// Makes the source ready before the session's clock starts, so that start() costs nothing:
  /// the simulated camera makes its thread and GL context and films one frame it throws away
  /// (the driver's first draw compiles its shaders: 100 ms, which would otherwise skip the first
  /// exposures). Optional: start() prepares a source not prepared.
  virtual Status prepare() { return Ok{}; }
  /// Starts the source's thread; `t0_ns` is the session's start (script time 0) [ns, monotonic].
  virtual Status start(std::int64_t t0_ns) = 0;
  /// The newest frame since the last call into `out`; false if none arrived.
  virtual bool take(CameraFrame* out) = 0;
  /// Blocks until a frame may be ready to take(), the source stops, or `deadline_ns` [ns,
  /// monotonic] passes, whichever is first; spurious returns are allowed. Sources that know when
  /// they publish wake the frame thread at once (a condition variable); this default polls every
  /// 0.5 ms.
  virtual void wait_for_frame(std::int64_t deadline_ns);
  /// True once the source has ended (end of a file) or failed (error() says why).
  virtual bool ended() const = 0;
  virtual std::string error() const = 0;
  /// Frames delivered so far (taken or dropped).
  virtual std::uint64_t delivered() const = 0;
  /// Frames the source itself failed to produce at its rate (a simulated camera on a busy
  /// machine); 0 for sources that deliver whatever they get.
  virtual std::uint64_t skipped() const { return 0; }
  /// Stops the thread. Idempotent.
  virtual void stop() = 0;
};

/// The synthetic camera filming the scripted user's true hands (`truth`), whose fingertips the
/// simulated device `dev` holds (their positions at each exposure come from its truth samples).
std::unique_ptr<FrameSource> make_synthetic_source(const vision::Camera& camera,
                                                   const std::array<hand::HandModel, 2>& truth,
                                                   const sim::RubiksTask& task,
                                                   device::SimulatedSpidar& dev, double fps,
                                                   std::uint64_t seed, bool bending_wrists = false);

/// The synthetic camera filming the interactively controlled hands (their commanded posture).
std::unique_ptr<FrameSource> make_interactive_source(const vision::Camera& camera,
                                                     const InteractiveHands& hands, double fps,
                                                     std::uint64_t seed);

/// A real camera (V4L2 device) or a video file, read in its own thread. A device's frames carry
/// the host time they were grabbed at; a file's frame k is shown at start + k / fps.
std::unique_ptr<FrameSource> make_capture_source(vision::Capture capture);

}  // namespace spidar::session
