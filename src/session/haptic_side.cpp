#include "spidar/session/haptic_side.hpp"

#include "spidar/core/clock.hpp"

namespace spidar::session {

HapticSide::HapticSide(device::Device& device, const strings::DeviceConfig& config,
                       physics::World& world, const physics::CouplingParams& coupling,
                       const HapticSideParams& params)
    : device_(device) {
  bridge_ = std::make_shared<sim::HapticForces>(coupling, params.servo.rate_hz);
  physics_ = std::make_unique<sim::PhysicsThread>(world, *bridge_);
  physics_->set_snapshot_proxies(params.snapshot_proxies);
  physics_->set_realtime_priority(params.physics_priority);
  loop_ = std::make_unique<device::ServoLoop>(device, config, params.servo, bridge_);
}

HapticSide::~HapticSide() { stop(); }

void HapticSide::set_before_step(std::function<void(physics::World&)> fn) {
  physics_->set_before_step(std::move(fn));
}

void HapticSide::start() {
  if (started_) return;
  if (auto st = device_.open(); !st) throw SpidarError("device: " + st.error().message);
  t_open_ns_ = core::monotonic_ns();
  started_ = true;
  physics_->start();
  if (auto st = loop_->start(); !st) {
    stop();
    throw SpidarError("servo loop: " + st.error().message);
  }
}

void HapticSide::stop() {
  if (stopped_) return;
  stopped_ = true;
  loop_->stop();
  physics_->stop();
  if (started_) device_.close();
}

}  // namespace spidar::session
