#pragma once
/// Where the (simulated) user wants each fingertip to be. The simulated device ties each
/// fingertip cap to its goal through a human-fingertip impedance, so displayed forces push the
/// fingertip away from the goal as a real finger yields.
#include <functional>
#include <span>

#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device {

class FingertipSource {
 public:
  virtual ~FingertipSource() = default;
  /// Goal positions p_W [m], world, of every fingertip at time t [s] since the device opened.
  /// Called from the device's thread; must not allocate.
  virtual void goals(double t_s, std::span<Vec3> p_W_goal) = 0;
  /// How stiffly each fingertip holds the goals of the last goals() call (the shape of its
  /// stiffness, world frame), or false to keep the device's isotropic impedance. A source that
  /// knows the user's hand gives the finger's own stiffness ellipsoid, so that the displayed
  /// forces move the fingertip only where the finger's joints can take it. Called right after
  /// goals(), from the same thread; must not allocate.
  virtual bool holds(std::span<FingertipHold> /*hold*/) { return false; }
};

/// Goals from a function of time (scripted trajectories).
class ScriptedFingertips final : public FingertipSource {
 public:
  using Script = std::function<void(double t_s, std::span<Vec3> p_W_goal)>;
  explicit ScriptedFingertips(Script script) : script_(std::move(script)) {}
  void goals(double t_s, std::span<Vec3> p_W_goal) override { script_(t_s, p_W_goal); }

 private:
  Script script_;
};

/// A rest point per finger of a device config: 15 % of the way from the frame centre toward the
/// mean of its fulcrums (each finger's own side of the workspace) [m], world.
std::vector<Vec3> rest_points(const strings::DeviceConfig& config);

/// Every fingertip circles slowly (radius 1 cm, 0.5 Hz, phase per finger) around a rest point
/// `offset` from the frame centre toward its own fulcrums' side: a hand hovering in the frame.
ScriptedFingertips::Script hovering_hands(std::span<const Vec3> p_W_rest);

}  // namespace spidar::device
