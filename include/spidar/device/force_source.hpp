#pragma once
/// Where the servo loop gets the forces to display each cycle.
#include "spidar/core/seqlock.hpp"
#include "spidar/device/servo_types.hpp"

namespace spidar::device {

class ForceSource {
 public:
  virtual ~ForceSource() = default;
  /// Called in the servo cycle: must not block, allocate or lock. `out.t_ns` must say how fresh
  /// the forces are.
  virtual void forces(const FingertipSample& in, ForceFrame& out) noexcept = 0;
};

/// Displays no force (strings at minimum tension): the state before physics is attached.
class ZeroForce final : public ForceSource {
 public:
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
    out.t_ns = in.t_ns;
    out.f_W = {};
  }
};

/// Forces published by another thread (e.g. physics) through a Latest<ForceFrame>.
class PublishedForces final : public ForceSource {
 public:
  core::Latest<ForceFrame>& input() { return input_; }
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override;

 private:
  core::Latest<ForceFrame> input_;
};

}  // namespace spidar::device
