#pragma once
/// The haptic side of a session (docs/architecture.md, "The flow of one session"): the servo loop driving a
/// device, the physics thread stepping the world, and the bridge between them (fingertip proxies,
/// coupling, passivity control). The Session and the haptic demo run it the same way.
#include <cstdint>
#include <functional>
#include <memory>

#include "spidar/device/device.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::session {

struct HapticSideParams {
  device::ServoConfig servo;
  /// SCHED_FIFO priority of the physics thread (0: normal scheduling).
  int physics_priority = 0;
  /// Whether the physics snapshots show the fingertip proxies (the frame side hides them: the
  /// fitted hands are drawn instead).
  bool snapshot_proxies = true;
};

class HapticSide {
 public:
  /// `device`, `config`, `world` must outlive this. Nothing starts yet.
  HapticSide(device::Device& device, const strings::DeviceConfig& config, physics::World& world,
             const physics::CouplingParams& coupling, const HapticSideParams& params);
  ~HapticSide();
  HapticSide(const HapticSide&) = delete;
  HapticSide& operator=(const HapticSide&) = delete;

  /// Runs inside the physics thread before every step (a cube monitor); set before start().
  void set_before_step(std::function<void(physics::World&)> fn);
  /// Opens the device, starts physics and the servo loop. Throws SpidarError ("device: ...",
  /// "servo loop: ...") with everything stopped again.
  void start();
  /// Stops the servo loop (device in its safe state) and physics, closes the device. Idempotent.
  void stop();
  bool started() const { return started_; }
  /// When the device was opened [ns, monotonic]; 0 before start().
  std::int64_t t_open_ns() const { return t_open_ns_; }

  device::ServoLoop& loop() { return *loop_; }
  const device::ServoLoop& loop() const { return *loop_; }
  sim::PhysicsThread& physics() { return *physics_; }
  const sim::PhysicsThread& physics() const { return *physics_; }
  const sim::HapticForces& bridge() const { return *bridge_; }

 private:
  device::Device& device_;
  std::shared_ptr<sim::HapticForces> bridge_;
  std::unique_ptr<sim::PhysicsThread> physics_;
  std::unique_ptr<device::ServoLoop> loop_;
  bool started_ = false, stopped_ = false;
  std::int64_t t_open_ns_ = 0;
};

}  // namespace spidar::session
