#pragma once
/// Whether a fingertip holds still: the calibration steps take a fingertip's sample only after
/// its strings have stayed within a tolerance for a moment, near the target by the present
/// calibration. Works on one finger's unwrapped encoder counts (device::UnwrappedCounts).
#include <cstdint>
#include <deque>
#include <span>
#include <utility>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::strings {

struct StabilityParams {
  double hold_s = 0.5;          ///< the fingertip must hold still this long [s]
  double tolerance_m = 0.0005;  ///< largest change of any of its strings while holding [m]
  double near_m = 0.03;         ///< and be this close to the target by the present calibration [m]
};

/// Watches one finger's counts; `ready()` once it has held still near the target for hold_s.
class StabilityCheck {
 public:
  /// `finger` must outlive the check; `p_W_target` [m], world.
  StabilityCheck(const FingerConfig& finger, const Vec3& p_W_target, StabilityParams params);
  /// A reading at time t [s] of this finger's strings (config order, unwrapped counts).
  void update(double t_s, std::span<const std::int64_t> counts);
  bool ready() const { return ready_; }
  double held_s() const { return held_s_; }          ///< how long it has held still so far [s]
  double spread_m() const { return spread_m_; }      ///< largest string change over the window [m]
  double distance_m() const { return distance_m_; }  ///< from the target, present calibration [m]
  const StabilityParams& params() const { return p_; }
  /// The mean counts over the hold window (rounded to counts).
  std::vector<std::int64_t> sample() const;

 private:
  const FingerConfig& finger_;
  Vec3 target_;
  StabilityParams p_;
  std::deque<std::pair<double, std::vector<std::int64_t>>> window_;
  bool ready_ = false;
  double still_since_ = 0;  ///< when the present still stretch began [s]
  double held_s_ = 0, spread_m_ = 0, distance_m_ = 1e9;
};

}  // namespace spidar::strings
