#pragma once
// Test support: the bracelet band's near side sampled densely and projected, written out from
// the band's ellipse section (independently of residuals.cpp's prediction), for tests that
// compare a prediction with what a camera would see of the band.
#include <cmath>
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration::testing {

/// The image points [px] of the band around a forearm whose frame has rotation R_WF [world] at the
/// wrist p_W_wrist: `along` + 1 sections across the band's width, `around` points on each, those
/// whose outward normal faces the camera (the near side).
inline std::vector<Vec2> band_near_side_points(const Mat3& R_WF, const Vec3& p_W_wrist, double hand_width_m,
                                               const vision::Camera& camera, const RegistrationParams& p,
                                               int along, int around) {
  const Vec3 x = R_WF.col(0), y = R_WF.col(1), z = R_WF.col(2);
  const double a = bracelet_radius_m(p, hand_width_m);
  const double b = p.bracelet_depth_ratio * p.bracelet_radius_per_width * hand_width_m + p.bracelet_standoff_m;
  std::vector<Vec2> pts;
  for (int j = 0; j <= along; ++j) {
    const double s = p.bracelet_offset_m + p.bracelet_width_m * (static_cast<double>(j) / along - 0.5);
    for (int k = 0; k < around; ++k) {
      const double phi = 2.0 * 3.14159265358979 * k / around;
      const Vec3 q = p_W_wrist - s * y + a * std::cos(phi) * x + b * std::sin(phi) * z;
      const Vec3 normal = (std::cos(phi) / a) * x + (std::sin(phi) / b) * z;
      if (normal.dot(camera.X_WC().p - q) <= 0) continue;
      pts.push_back(camera.project(q));
    }
  }
  return pts;
}

}  // namespace spidar::registration::testing
