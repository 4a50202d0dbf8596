#pragma once
/// A rig gives a session its device and its camera, and on the simulated rig the ground truth
/// (the user's true hands) and the user (scripted or interactive). New rigs (another lab's
/// device) implement this interface; a recording played back is one too (recording_rig.hpp).
#include <array>
#include <memory>
#include <string>

#include "spidar/device/device.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/session/frame_source.hpp"
#include "spidar/session/interactive_hands.hpp"
#include "spidar/session/scene.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

class Rig {
 public:
  virtual ~Rig() = default;
  /// True for a rig that plays a recording back: its frames carry the fingertip sample and the
  /// scene poses they were processed with live (CameraFrame::measured, scene_poses), so the
  /// session drives no device and runs no physics, and takes every frame in turn.
  virtual bool plays_back() const { return false; }
  /// The device the servo loop drives, and its string layout (not asked of a rig that plays back).
  virtual device::Device& device() = 0;
  virtual const strings::DeviceConfig& device_config() const = 0;
  /// The camera the frame thread takes frames from.
  virtual FrameSource& camera() = 0;
  /// The simulated user's true hands (left, right): the ground truth; null on real hardware.
  virtual const std::array<hand::HandModel, 2>* truth_hands() const { return nullptr; }
  /// The simulated user's hands under interactive control; null unless the rig has them.
  virtual InteractiveHands* interactive() { return nullptr; }
  /// For logs and recordings: "simulated SPIDAR-8", "serial /dev/ttyUSB0", ...
  virtual std::string name() const = 0;
};

struct SimulatedRigParams {
  std::uint64_t seed = 0;    ///< device noise and camera noise
  double fps = 30.0;         ///< synthetic camera rate [frames/s]
  bool interactive = false;  ///< the GUI moves the hands instead of the scene's script
  /// The user's forearms point at their elbows, which stay where the forearms pointed at the
  /// script's start; the wrists bend (up to 60°) when the hands turn (sim::user_elbows). Off: the
  /// forearms stay in line with the hands, as the registration's model has them. Only the scripted
  /// user's synthetic camera (not `interactive`, not another camera).
  bool bending_wrists = true;
};

/// The simulated SPIDAR-8 held by a simulated user (the scene's script, or interactive hands
/// between the script's open start and its grip), filmed by the synthetic camera unless another
/// camera is given (a real camera filming while the device is simulated).
class SimulatedRig final : public Rig {
 public:
  SimulatedRig(const strings::DeviceConfig& config, const Scene& scene, const vision::Camera& camera,
               const std::array<hand::HandModel, 2>& user, const SimulatedRigParams& params,
               std::unique_ptr<FrameSource> other_camera = nullptr);
  device::Device& device() override { return *device_; }
  const strings::DeviceConfig& device_config() const override { return config_; }
  FrameSource& camera() override { return *camera_; }
  const std::array<hand::HandModel, 2>* truth_hands() const override { return &user_; }
  InteractiveHands* interactive() override { return interactive_.get(); }
  std::string name() const override { return "simulated " + config_.name; }
  device::SimulatedSpidar& simulated() { return *device_; }

 private:
  strings::DeviceConfig config_;
  std::array<hand::HandModel, 2> user_;
  std::shared_ptr<InteractiveHands> interactive_;
  std::unique_ptr<device::SimulatedSpidar> device_;
  std::unique_ptr<FrameSource> camera_;
};

/// A real device (any backend: serial transport, a lab's own) and a real camera or video file.
class HardwareRig final : public Rig {
 public:
  HardwareRig(const strings::DeviceConfig& config, std::unique_ptr<device::Device> device,
              std::unique_ptr<FrameSource> camera, std::string name)
      : config_(config), device_(std::move(device)), camera_(std::move(camera)), name_(std::move(name)) {}
  device::Device& device() override { return *device_; }
  const strings::DeviceConfig& device_config() const override { return config_; }
  FrameSource& camera() override { return *camera_; }
  std::string name() const override { return name_; }

 private:
  strings::DeviceConfig config_;
  std::unique_ptr<device::Device> device_;
  std::unique_ptr<FrameSource> camera_;
  std::string name_;
};

}  // namespace spidar::session
