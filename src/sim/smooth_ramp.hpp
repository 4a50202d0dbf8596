#pragma once
/// The scripted users' motion profile (private to sim).
#include <algorithm>

namespace spidar::sim {

/// 0 before t0, 1 after t1, smooth in between (smoothstep: zero velocity at both ends).
inline double ramp(double t, double t0, double t1) {
  const double x = std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace spidar::sim
