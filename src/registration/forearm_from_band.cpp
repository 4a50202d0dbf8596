#include "spidar/registration/forearm_from_band.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spidar/core/units.hpp"
#include "spidar/hand/forearm.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration {
namespace {

/// The forearm bent by `bend` [rad] from −y_H toward x_H cos φ + z_H sin φ (right-hand H, unit).
Vec3 bent_forearm_H(double bend, double phi) {
  return {std::sin(bend) * std::cos(phi), -std::cos(bend), std::sin(bend) * std::sin(phi)};
}

}  // namespace

std::optional<Vec3> forearm_from_band(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                                      const RegistrationParams& params, const BandObservation& band,
                                      const Vec3* previous_H) {
  const RegistrationParams& o = params;  // the forearm_* settings
  const Vec2 axis_obs = band.end_b_px - band.end_a_px;
  if (!(band.fill >= kForearmBandMinFill) || !(band.length_px > 1.0) || !(band.thickness_px > 0.5) ||
      !(axis_obs.norm() > 1e-6) || !axis_obs.allFinite() || !X_WH.p.allFinite())
    return std::nullopt;
  if (!(o.forearm_max_bend_rad > 0)) return std::nullopt;
  const Vec2 axis_unit = axis_obs.normalized();
  const Vec2 across(-axis_unit.y(), axis_unit.x());
  const Mat3 R = X_WH.R.toRotationMatrix();
  const double elongation_obs = std::clamp(1.0 - band.thickness_px / band.length_px, 0.0, 1.0);
  const double bulge_obs = std::isfinite(band.bulge_px) ? band.bulge_px / band.thickness_px : 0.0;
  // The cost of the forearm bent_forearm_H(bend, φ); +∞ where its band is not in front of the camera.
  auto cost_of = [&](double bend, double phi) {
    const Vec3 d_H = bent_forearm_H(bend, phi);
    const Pose X_WF = hand::forearm_pose(X_WH, R * d_H);
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const BandProfile profile = bracelet_band_profile(X_WF, hand_width_m, camera, params, across,
                                                         kForearmBandSamplesPerRim);
    const double thickness = profile.hi_px - profile.lo_px;
    if (!(thickness > 0)) return kInf;
    const auto ends = bracelet_band_ends(X_WF, hand_width_m, camera.X_WC().p, params);
    if (camera.depth(ends[0]) < 1e-3 || camera.depth(ends[1]) < 1e-3) return kInf;
    const Vec2 axis_pred = camera.project(ends[1]) - camera.project(ends[0]);
    if (!(axis_pred.norm() > 1e-6)) return kInf;
    // The long axis's angle, either sign, counted as far as the band is elongated.
    const double c = std::abs(axis_pred.normalized().dot(axis_unit));
    const double angle = std::acos(std::clamp(c, 0.0, 1.0));
    const double r_t = (thickness / band.thickness_px - 1.0) / o.forearm_thickness_sigma;
    const double r_a = elongation_obs * angle / o.forearm_axis_sigma_rad;
    const double r_b = bend / o.forearm_bend_sigma_rad;
    // The crescent's side: its area's centroid against the middle of its extent, per thickness.
    const double bulge_pred = (profile.centroid_px - 0.5 * (profile.lo_px + profile.hi_px)) / thickness;
    const double r_g = (bulge_pred - bulge_obs) / o.forearm_bulge_sigma;
    double cost = r_t * r_t + r_a * r_a + r_b * r_b + r_g * r_g;
    if (previous_H && previous_H->allFinite()) {
      const double a = std::acos(std::clamp(previous_H->normalized().dot(d_H), -1.0, 1.0));
      cost += (a / o.forearm_previous_sigma_rad) * (a / o.forearm_previous_sigma_rad);
    }
    return cost;
  };
  double best = std::numeric_limits<double>::infinity(), best_bend = 0, best_phi = 0;
  auto consider = [&](double bend, double phi) {
    bend = std::clamp(bend, 0.0, o.forearm_max_bend_rad);
    const double c = cost_of(bend, phi);
    if (c < best) best = c, best_bend = bend, best_phi = phi;
  };
  // A coarse grid over the cone, and the last estimate itself (a track keeps its basin) ...
  for (int i = 0; i <= kForearmBendSteps; ++i) {
    const int azimuths = i == 0 ? 1 : kForearmAzimuthSteps;
    for (int k = 0; k < azimuths; ++k)
      consider(o.forearm_max_bend_rad * i / kForearmBendSteps, 2.0 * units::kPi * k / azimuths);
  }
  if (previous_H && previous_H->allFinite() && previous_H->norm() > 1e-9) {
    const Vec3 d = previous_H->normalized();
    consider(std::acos(std::clamp(-d.y(), -1.0, 1.0)), std::atan2(d.z(), d.x()));
  }
  if (!std::isfinite(best)) return std::nullopt;
  // ... then refined around the best, the steps halved each round.
  double step_bend = 0.5 * o.forearm_max_bend_rad / kForearmBendSteps;
  double step_phi = units::kPi / kForearmAzimuthSteps;
  for (int round = 0; round < kForearmRefinements; ++round, step_bend *= 0.5, step_phi *= 0.5) {
    const double b0 = best_bend, p0 = best_phi;
    for (int db = -1; db <= 1; ++db)
      for (int dp = -1; dp <= 1; ++dp)
        if (db != 0 || dp != 0) consider(b0 + db * step_bend, p0 + dp * step_phi);
  }
  return bent_forearm_H(best_bend, best_phi);
}

}  // namespace spidar::registration
