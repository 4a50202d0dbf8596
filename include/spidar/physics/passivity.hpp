#pragma once
/// Passivity observer and controller for one haptic port (Hannaford & Ryu 2002).
///
/// Convention: F is the force the device applies to the user's fingertip [N], v the fingertip
/// velocity [m/s]. F·v is the power delivered to the user. The virtual side is passive while the
/// energy it has absorbed, E = −Σ F·v·Δt, stays ≥ 0 (it may store and dissipate, never create).
/// When E goes negative the controller adds just enough damping, F' = F − α v, to bring it back.
#include <cstdint>

#include "spidar/core/types.hpp"

namespace spidar::physics {

struct PassivityStats {
  double energy = 0;          ///< E [J]: energy absorbed by the virtual side
  double min_energy = 0;      ///< lowest E seen [J]
  double dissipated = 0;      ///< energy the controller removed [J]
  std::uint64_t active_steps = 0;  ///< steps where the controller had to act
};

class PassivityPort {
 public:
  /// With `control` false it only observes.
  explicit PassivityPort(bool control = true, double max_damping = 50.0)
      : control_(control), max_damping_(max_damping) {}

  /// Observes one servo step and returns the force to display (F, or F − α v when the port
  /// would otherwise turn active). dt [s].
  Vec3 step(const Vec3& f_W, const Vec3& v_W, double dt);
  const PassivityStats& stats() const { return stats_; }
  void reset() { stats_ = {}; }

 private:
  bool control_;
  double max_damping_;
  PassivityStats stats_;
};

}  // namespace spidar::physics
