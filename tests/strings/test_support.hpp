#pragma once
#include <random>
#include <string>

#include "spidar/strings/device_config.hpp"

namespace spidar::strings::testing {

inline std::string source_path(const std::string& rel) { return std::string(SPIDAR_SOURCE_DIR) + "/" + rel; }

inline const DeviceConfig& spidar8() {
  static const DeviceConfig cfg = load_device_config(source_path("configs/spidar8.yaml"));
  return cfg;
}
inline const DeviceConfig& spidar_g4() {
  static const DeviceConfig cfg = load_device_config(source_path("configs/spidar-g4.yaml"));
  return cfg;
}

/// A random fingertip position in the working volume: within `half` of the centre and on the
/// inner side of the closed-form triple's plane by at least 2 cm.
inline Vec3 random_workspace_point(const PointGeometry& g, std::mt19937_64& rng, double half) {
  std::uniform_real_distribution<double> u(-half, half);
  for (;;) {
    const Vec3 p = g.p_W_inner + Vec3(u(rng), u(rng), u(rng));
    if (g.triple.n3_inner.dot(p - g.triple.p_WA1) > 0.02) return p;
  }
}

}  // namespace spidar::strings::testing
