// The forearm's direction from its band: a band drawn around a bent forearm (its ends and near-side
// extent written out here from the ellipse section, independently of the estimate's prediction) is
// explained best by that bend; a band that is no evidence gives none.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>

#include "spidar/hand/forearm.hpp"
#include "spidar/registration/forearm_from_band.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/vision/camera.hpp"
#include "band_near_side_points.hpp"

namespace spidar::registration {
namespace {

// The band around a forearm along d_W from a wrist at X_WH, seen by `camera`: its near side's
// points (both rims, outward normal toward the camera) projected densely, their principal extent
// and the extent across it.
BandObservation draw_band(const Pose& X_WH, const Vec3& d_W, double width, const vision::Camera& camera,
                          const RegistrationParams& p) {
  const Mat3 R = hand::wrist_bend(X_WH.R.toRotationMatrix(), d_W) * X_WH.R.toRotationMatrix();
  const std::vector<Vec2> pts = testing::band_near_side_points(R, X_WH.p, width, camera, p, 40, 720);
  // Principal axis of the points (their covariance), then the extents.
  Vec2 mean = Vec2::Zero();
  for (const Vec2& q : pts) mean += q;
  mean /= static_cast<double>(pts.size());
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
  for (const Vec2& q : pts) C += (q - mean) * (q - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(C);
  const Vec2 u = es.eigenvectors().col(1), v = es.eigenvectors().col(0);
  double lo_u = 1e9, hi_u = -1e9, lo_v = 1e9, hi_v = -1e9;
  for (const Vec2& q : pts) {
    lo_u = std::min(lo_u, (q - mean).dot(u)), hi_u = std::max(hi_u, (q - mean).dot(u));
    lo_v = std::min(lo_v, (q - mean).dot(v)), hi_v = std::max(hi_v, (q - mean).dot(v));
  }
  // The pixels the points fall in, as a detector sees the band: the bulge is their centroid
  // against the middle of their extent across u, along (−u_y, u_x).
  std::set<std::pair<long, long>> pixels;
  for (const Vec2& q : pts) pixels.insert({std::lround(q.x()), std::lround(q.y())});
  const Vec2 across(-u.y(), u.x());
  double s_sum = 0, s_lo = 1e9, s_hi = -1e9;
  for (const auto& [px, py] : pixels) {
    const double s = Vec2(static_cast<double>(px), static_cast<double>(py)).dot(across);
    s_sum += s, s_lo = std::min(s_lo, s), s_hi = std::max(s_hi, s);
  }
  BandObservation band;
  band.bulge_px = s_sum / static_cast<double>(pixels.size()) - 0.5 * (s_lo + s_hi);
  band.end_a_px = mean + lo_u * u;
  band.end_b_px = mean + hi_u * u;
  band.length_px = hi_u - lo_u;
  band.thickness_px = hi_v - lo_v;
  band.fill = 0.8;
  return band;
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / 3.14159265358979;
}

TEST(ForearmFromBand, FindsTheBendTheBandShows) {
  RegistrationParams p;
  const vision::Camera camera = vision::default_rig_camera();
  const double width = 0.083;
  // A hand below the camera, fingers away from it; its forearm bent by 0°, 30° or 50°, toward or
  // away from the camera, or sideways.
  const Vec3 target = camera.X_WC().p + 0.45 * camera.ray_direction_W(Vec2(320, 260));
  const Pose X_WH = Pose::FromRotationVector(Vec3(0.2, -0.3, 0.4), target);
  const Mat3 R = X_WH.R.toRotationMatrix();
  int checked = 0;
  for (const double bend_deg : {0.0, 30.0, 50.0}) {
    for (const Vec3& toward : {Vec3(R.col(2)), Vec3(-R.col(2)), Vec3(R.col(0))}) {
      const double bend = bend_deg * 3.14159265358979 / 180.0;
      const Vec3 d_W = (std::cos(bend) * -R.col(1) + std::sin(bend) * toward).normalized();
      const BandObservation band = draw_band(X_WH, d_W, width, camera, p);
      ASSERT_GT(band.length_px, 10.0);
      // The last estimate near the truth (a track), as the pipeline gives it: the two signs of a
      // tilt along the line of sight look alike, the track keeps the right one.
      const Vec3 last_H = R.transpose() * d_W;
      const auto est = forearm_from_band(X_WH, width, camera, p, band, &last_H);
      ASSERT_TRUE(est.has_value());
      EXPECT_LT(angle_deg(R * *est, d_W), 12.0) << "bend " << bend_deg << " toward " << toward.transpose();
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

// A tilt toward the camera and one away from it give bands of nearly the same thickness and axis;
// the crescent's bulge tells them apart without a track. Without the bulge, the sign is a guess.
TEST(ForearmFromBand, TheCrescentsSideTellsATiltTowardTheCameraFromOneAway) {
  RegistrationParams with_bulge, without_bulge;
  without_bulge.forearm_bulge_sigma = 100.0;
  const vision::Camera camera = vision::default_rig_camera();
  const double width = 0.083;
  const Vec3 target = camera.X_WC().p + 0.45 * camera.ray_direction_W(Vec2(320, 260));
  const Pose X_WH = Pose::FromRotationVector(Vec3(0.2, -0.3, 0.4), target);
  const Mat3 R = X_WH.R.toRotationMatrix();
  int right_with = 0, right_without = 0, cases = 0;
  for (const double bend_deg : {35.0, 50.0}) {
    for (const double sign : {1.0, -1.0}) {
      // Bent toward ±z_H (dorsal or palmar): toward or away from the camera above the hand.
      const double bend = bend_deg * 3.14159265358979 / 180.0;
      const Vec3 d_W = (std::cos(bend) * -R.col(1) + sign * std::sin(bend) * R.col(2)).normalized();
      const Vec3 mirror_W = (std::cos(bend) * -R.col(1) - sign * std::sin(bend) * R.col(2)).normalized();
      const BandObservation band = draw_band(X_WH, d_W, width, camera, with_bulge);
      ASSERT_GT(band.length_px, 10.0);
      for (const bool bulge : {true, false}) {
        const auto est = forearm_from_band(X_WH, width, camera, bulge ? with_bulge : without_bulge, band, nullptr);
        ASSERT_TRUE(est.has_value());
        const double err = angle_deg(R * *est, d_W), err_mirror = angle_deg(R * *est, mirror_W);
        std::printf("bend %.0f° sign %+.0f, %s bulge (%.2f of %.1f px): error %.1f°, to the mirror %.1f°\n", bend_deg,
                    sign, bulge ? "with" : "without", band.bulge_px, band.thickness_px, err, err_mirror);
        if (bulge) {
          EXPECT_LT(err, 20.0) << "bend " << bend_deg << " sign " << sign;
          right_with += err < err_mirror ? 1 : 0;
        } else {
          right_without += err < err_mirror ? 1 : 0;
        }
      }
      ++cases;
    }
  }
  EXPECT_EQ(right_with, cases);
  EXPECT_LT(right_without, cases) << "the bulge is what tells the sign here";
}

TEST(ForearmFromBand, ABandThatIsNoEvidenceGivesNone) {
  RegistrationParams p;
  const vision::Camera camera = vision::default_rig_camera();
  const Pose X_WH = Pose::FromRotationVector(Vec3(0.2, -0.3, 0.4),
                                             camera.X_WC().p + 0.45 * camera.ray_direction_W(Vec2(320, 260)));
  BandObservation band = draw_band(X_WH, -(X_WH.R * Vec3::UnitY()), 0.083, camera, p);
  BandObservation torn = band;
  torn.fill = 0.1;
  EXPECT_FALSE(forearm_from_band(X_WH, 0.083, camera, p, torn, nullptr).has_value());
  BandObservation nan = band;
  nan.end_a_px.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(forearm_from_band(X_WH, 0.083, camera, p, nan, nullptr).has_value());
  BandObservation flat = band;
  flat.thickness_px = 0.0;
  EXPECT_FALSE(forearm_from_band(X_WH, 0.083, camera, p, flat, nullptr).has_value());
  Pose broken = X_WH;
  broken.p.x() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(forearm_from_band(broken, 0.083, camera, p, band, nullptr).has_value());
  // Without a last estimate the in-line forearm's band gives a direction near in line.
  const auto est = forearm_from_band(X_WH, 0.083, camera, p, band, nullptr);
  ASSERT_TRUE(est.has_value());
  EXPECT_LT(angle_deg(*est, Vec3(0, -1, 0)), 20.0);
}

}  // namespace
}  // namespace spidar::registration
