#pragma once
/// The live mixed-reality session (`spidar-mr run`): a LiveConfig wired into a rig (the simulated
/// SPIDAR-8 or a serial device; the synthetic camera, a V4L2 device or a video file), a
/// Session and its sinks — the GUI's view model (FrameStatsSink) and, when
/// asked for, the recorder. The caller steps it on its thread (GL context current) and shows the
/// results (window, GUI) or not (headless).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "spidar/device/servo_loop.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/frame_stats.hpp"
#include "spidar/session/interactive_hands.hpp"
#include "spidar/session/live_config.hpp"
#include "spidar/session/rig.hpp"
#include "spidar/session/scene.hpp"
#include "spidar/session/session.hpp"
#include "spidar/session/session_recorder.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::session {

using LiveFrameStats = FrameStats;

/// The pipeline parameters a live config asks for (shared by run and replay, so both fit alike).
pipeline::FramePipelineParams live_pipeline_params(const LiveConfig& c,
                                                   const std::array<Vec3, 2>& initial_r_W_hand);

struct LiveSessionOptions {
  std::string record_dir;             ///< empty: no recording
  FrameStore record_frames = FrameStore::kVideo;
  /// The pipeline's warm-up before the clock starts (SessionParams::warm_up). The GUI
  /// skips it: its window is up already, and the warm-up (~0.3 s, seconds on a loaded machine)
  /// would only delay the first frame the user sees.
  bool warm_up = true;
};

class LiveSession {
 public:
  /// Loads everything the config names and builds the threads (not started). Throws UsageError /
  /// core::ConfigError with what and where. `context` must be current on the calling thread.
  static std::unique_ptr<LiveSession> create(const LiveConfig& config, render::Context& context,
                                             const LiveSessionOptions& options = {});
  ~LiveSession();
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  /// Opens the device (a missing port is an error here, not a hang) and starts the threads.
  void start();
  /// Processes the newest camera frame if one arrived since the last call; false if none did.
  /// Throws SpidarError if the pipeline fails.
  bool step();
  /// Blocks until a frame may be ready for step(), or `deadline_ns` [ns, monotonic].
  void wait_for_frame(std::int64_t deadline_ns);
  /// False once the servo loop ended (a device fault) or the camera ended (end of a file) or
  /// failed (error() says why).
  bool running() const { return session_->running(); }
  std::string error() const;
  /// True once the camera has ended (end of a file) or failed.
  bool camera_ended() const { return rig_->camera().ended(); }
  /// Stops every thread (device left in its safe state) and finishes the recording. Idempotent.
  void stop();

  // --- for the GUI and the report ---
  const LiveConfig& config() const { return config_; }
  const strings::DeviceConfig& device_config() const { return rig_->device_config(); }
  /// The camera the composite is drawn in: the calibration's, or its lens's pinhole camera (the
  /// frames undistorted on arrival; Session::camera()).
  const vision::Camera& camera() const { return session_->camera(); }
  const std::array<hand::HandModel, 2>& models() const { return models_; }
  /// The GUI's view model: the last processed frame, the bounded history, the run's means.
  const FrameStatsSink& view() const { return view_; }
  /// The last processed frame: camera image and pipeline result (empty before the first).
  const cv::Mat& camera_image() const { return view_.camera_image(); }
  const pipeline::FrameResult& result() const { return view_.result() ? *view_.result() : no_result_; }
  const device::FingertipSample& measured() const { return view_.measured(); }
  const HistoryRing<LiveFrameStats>& history() const { return view_.history(); }
  std::uint64_t frames() const { return session_->frames(); }
  std::uint64_t camera_frames() const { return session_->camera_frames(); }
  device::ServoLoop& servo() { return session_->servo(); }
  const device::ServoLoop& servo() const { return session_->servo(); }
  std::optional<CubeStatus> cube_status() const { return scene_->monitor->status().read(); }
  CubeMonitor& cube() { return *scene_->monitor; }
  sim::PhysicsThreadStats physics_stats() const { return session_->physics_stats(); }
  const SessionRecorder* recorder() const { return recorder_.get(); }
  /// The newest servo cycle at the device boundary (raw counts, commands); any thread.
  std::optional<DeviceCycleRecord> newest_device_cycle() const;
  /// The simulated user's hands under interactive control; null unless hands.control is
  /// interactive.
  InteractiveHands* interactive() { return rig_->interactive(); }
  double seconds() const { return session_->seconds(); }

 private:
  LiveSession() = default;
  LiveConfig config_;
  vision::Camera camera_;
  std::array<hand::HandModel, 2> models_, user_models_;
  std::unique_ptr<Scene> scene_;
  std::unique_ptr<Rig> rig_;
  std::unique_ptr<RecordingDevice> recording_device_;
  std::unique_ptr<SessionRecorder> recorder_;
  FrameStatsSink view_;
  std::unique_ptr<Session> session_;
  pipeline::FrameResult no_result_;
};

}  // namespace spidar::session
