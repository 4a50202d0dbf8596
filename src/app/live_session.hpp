#pragma once
/// The live mixed-reality session (`spidar-mr run`): built from a LiveConfig, it runs the threads
/// of DESIGN.md — servo loop (device backend: simulated or serial), physics, camera (synthetic,
/// V4L2 device or video file) — and, on the caller's thread (the frame thread, GL context
/// current), takes camera frames through pipeline::FramePipeline: chroma key, bracelets,
/// registration, render, composite. The caller shows the results (window, GUI) or not (headless).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "spidar/session/interactive_hands.hpp"
#include "live_config.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/scripted_task.hpp"
#include "spidar/session/servo_timing.hpp"
#include "session_recorder.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/context.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::app {

/// Numbers of one processed frame (no ground truth: these are what a live session can measure).
struct LiveFrameStats {
  double t_s = 0;             ///< exposure time since the session started [s]
  double iou = 0;             ///< fitted hands' pixels vs the chroma-key silhouette
  std::array<registration::TermCosts, 2> terms{};  ///< final registration cost per term, per hand
  std::array<int, 2> iterations{};
  double latency_ms = 0;      ///< exposure to composite
  double pipeline_ms = 0;
  double registration_ms = 0;
  double servo_rate_hz = 0;   ///< since the previous frame
  double servo_jitter_max_us = 0;
};

/// IoU of the fitted hands (hand-id target, forearm included) against the chroma-key silhouette.
double silhouette_iou(const pipeline::FrameResult& r, cv::Mat* scratch);

/// The pipeline parameters a live config asks for (shared by run and replay, so both fit alike).
pipeline::FramePipelineParams live_pipeline_params(const LiveConfig& c,
                                                   const std::array<Vec3, 2>& initial_r_W_hand);

struct LiveSessionOptions {
  std::string record_dir;             ///< empty: no recording
  FrameStore record_frames = FrameStore::kVideo;
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
  /// False once the servo loop ended (a device fault) or the camera ended (end of a file) or
  /// failed (error() says why).
  bool running() const;
  std::string error() const;
  /// True once the camera has ended (end of a file) or failed.
  bool camera_ended() const;
  /// Stops every thread (device left in its safe state) and finishes the recording. Idempotent.
  void stop();

  // --- for the GUI and the report ---
  const LiveConfig& config() const { return config_; }
  const strings::DeviceConfig& device_config() const { return device_config_; }
  const vision::Camera& camera() const { return camera_; }
  const std::array<hand::HandModel, 2>& models() const { return models_; }
  /// The last processed frame: camera image and pipeline result (valid after step() returned true).
  const cv::Mat& camera_image() const { return camera_image_; }
  const pipeline::FrameResult& result() const { return result_; }
  const device::FingertipSample& measured() const { return measured_; }
  const std::vector<LiveFrameStats>& history() const { return history_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t camera_frames() const;  ///< frames the camera delivered (processed or dropped)
  device::ServoLoop& servo() { return *loop_; }
  const device::ServoLoop& servo() const { return *loop_; }
  std::optional<session::CubeStatus> cube_status() const;
  session::CubeMonitor& cube() { return *cube_monitor_; }
  sim::PhysicsThreadStats physics_stats() const;
  const SessionRecorder* recorder() const { return recorder_.get(); }
  /// The newest servo cycle at the device boundary (raw counts, commands); any thread.
  std::optional<DeviceCycleRecord> newest_device_cycle() const;
  /// The simulated user's hands under interactive control; null unless hands.control is
  /// interactive.
  session::InteractiveHands* interactive() { return interactive_.get(); }
  double seconds() const;  ///< since start()

  struct FrameSource;

 private:
  LiveSession() = default;
  LiveConfig config_;
  LiveSessionOptions options_;
  strings::DeviceConfig device_config_;
  vision::Camera camera_;
  std::array<hand::HandModel, 2> models_, user_models_;
  std::unique_ptr<physics::World> world_;
  std::optional<physics::RubiksCube> cube_;
  std::unique_ptr<session::CubeMonitor> cube_monitor_;
  std::shared_ptr<sim::RubiksTask> task_;
  std::shared_ptr<session::InteractiveHands> interactive_;
  std::unique_ptr<device::Device> device_;
  std::unique_ptr<RecordingDevice> recording_device_;
  std::shared_ptr<sim::HapticForces> bridge_;
  std::unique_ptr<sim::PhysicsThread> physics_;
  std::unique_ptr<device::ServoLoop> loop_;
  std::unique_ptr<FrameSource> source_;
  std::unique_ptr<pipeline::FramePipeline> pipe_;
  std::unique_ptr<SessionRecorder> recorder_;
  render::Context* context_ = nullptr;

  std::int64_t t_open_ns_ = 0;
  bool started_ = false, stopped_ = false;
  std::vector<device::FingertipSample> servo_buf_;
  SceneSnapshot scene_;
  cv::Mat camera_image_, iou_scratch_;
  pipeline::FrameResult result_;
  device::FingertipSample measured_;
  std::vector<LiveFrameStats> history_;
  std::uint64_t frames_ = 0;
  std::int64_t last_servo_t_ = 0;
};

}  // namespace spidar::app
