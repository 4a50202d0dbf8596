#include "spidar/device/fingertip_source.hpp"

#include <cmath>
#include <vector>

#include "spidar/core/units.hpp"

namespace spidar::device {

std::vector<Vec3> rest_points(const strings::DeviceConfig& config) {
  std::vector<Vec3> rest;
  for (const auto& f : config.fingers) {
    Vec3 mean = Vec3::Zero();
    for (int i = 0; i < f.geometry.n; ++i) mean += f.geometry.p_WA[i];
    mean /= f.geometry.n;
    rest.push_back(config.p_W_centre + 0.15 * (mean - config.p_W_centre));
  }
  return rest;
}

ScriptedFingertips::Script hovering_hands(std::span<const Vec3> p_W_rest) {
  std::vector<Vec3> rest(p_W_rest.begin(), p_W_rest.end());
  return [rest](double t, std::span<Vec3> goal) {
    for (std::size_t f = 0; f < goal.size() && f < rest.size(); ++f) {
      const double phase = 2.0 * units::kPi * (0.5 * t + 0.125 * static_cast<double>(f));
      goal[f] = rest[f] + 0.01 * Vec3(std::cos(phase), std::sin(phase), 0.5 * std::sin(2 * phase));
    }
  };
}

}  // namespace spidar::device
