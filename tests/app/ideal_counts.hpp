#pragma once
// The counts an ideal encoder of each of a finger's strings reads with the fingertip at p (its
// calibration channels, rounded to whole counts): the calibration steps' tests feed these.
#include <cmath>
#include <cstdint>
#include <vector>

#include "spidar/strings/device_config.hpp"

namespace spidar::test {

inline std::vector<std::int64_t> counts_at(const strings::FingerConfig& f, const Vec3& p) {
  std::vector<std::int64_t> c;
  for (int i = 0; i < f.geometry.n; ++i) {
    const double l = (f.geometry.p_WA[i] - p).norm();
    c.push_back(std::llround((l - f.channels[i].length_at_zero) / (f.channels[i].sign * f.channels[i].metres_per_count)));
  }
  return c;
}

}  // namespace spidar::test
