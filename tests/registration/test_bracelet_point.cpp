// Where the wrist term expects the bracelet's detected midpoint: the band centre moved toward the
// camera across the forearm (registration_params.hpp). Checked against the geometry of a cylinder
// written out independently: the point lies on the forearm's cross-section through the band
// centre, at the set share of the band's radius from the axis, on the camera's side.
#include <gtest/gtest.h>

#include <cmath>

#include "spidar/registration/residuals.hpp"

namespace spidar::registration {
namespace {

TEST(BraceletVisiblePoint, LiesOnTheBandsCrossSectionTowardTheCamera) {
  RegistrationParams p;
  p.bracelet_offset_m = 0.012;
  p.bracelet_surface_shift = 0.5;
  p.bracelet_radius_per_width = 0.31;
  p.bracelet_standoff_m = 0.002;
  const double width = 0.085;
  const double r = 0.31 * width + 0.002;
  for (const Vec3& rot : {Vec3(0, 0, 0), Vec3(0.3, -0.2, 1.0), Vec3(-1.2, 0.4, 0.1)}) {
    const Pose X_WH = Pose::FromRotationVector(rot, Vec3(0.05, -0.02, 0.1));
    const Vec3 camera(0.0, -0.5, 0.4);
    Vec3 shift;
    const Vec3 q = bracelet_visible_point(X_WH, width, camera, p, &shift);
    const Vec3 centre = X_WH.p + X_WH.R * Vec3(0, -0.012, 0);
    const Vec3 axis = X_WH.R * Vec3::UnitY();
    EXPECT_NEAR((q - centre).dot(axis), 0.0, 1e-12);          // in the cross-section
    EXPECT_NEAR((q - centre).norm(), 0.5 * r, 1e-12);         // half the radius off the axis
    EXPECT_NEAR((q - centre - shift).norm(), 0.0, 1e-12);
    // On the camera's side: nearer the camera than the centre, and the nearest such point.
    EXPECT_LT((camera - q).norm(), (camera - centre).norm());
    const Vec3 u = (q - centre).normalized(), v = axis.cross(u);
    for (double a : {0.3, -0.3, 1.5, 3.0}) {
      const Vec3 other = centre + 0.5 * r * (std::cos(a) * u + std::sin(a) * v);
      EXPECT_GT((camera - other).norm(), (camera - q).norm()) << "angle " << a;
    }
  }
  // Shift 0: the band centre itself (the paper's "the bracelet marks the wrist").
  p.bracelet_surface_shift = 0.0;
  Pose X;
  EXPECT_NEAR((bracelet_visible_point(X, width, Vec3(0, -1, 0.5), p) - Vec3(0, -0.012, 0)).norm(), 0.0, 1e-15);
  // A camera on the forearm's axis sees no side: no shift, no NaN.
  p.bracelet_surface_shift = 0.5;
  const Vec3 on_axis = bracelet_visible_point(X, width, Vec3(0, -1, 0), p);
  EXPECT_TRUE(on_axis.allFinite());
  EXPECT_NEAR((on_axis - Vec3(0, -0.012, 0)).norm(), 0.0, 1e-12);
}

// A bent wrist (HandObservation::forearm_H): the band sits along the forearm's own direction, and
// the point on its cross-section there, not on the hand's axis.
TEST(BraceletVisiblePoint, FollowsABentForearm) {
  RegistrationParams p;
  p.bracelet_offset_m = 0.012;
  p.bracelet_surface_shift = 0.5;
  const double width = 0.08;
  const double r = bracelet_radius_m(p, width);
  const Vec3 camera(0.02, -0.45, 0.5);
  for (const Vec3& bend : {Vec3(0.5, -0.8, 0.3), Vec3(0.0, -0.6, -0.8), Vec3(-0.7, -0.7, 0.0)}) {
    const Vec3 forearm_H = bend.normalized();
    for (const Vec3& rot : {Vec3(0, 0, 0), Vec3(0.3, -0.2, 1.0)}) {
      const Pose X_WH = Pose::FromRotationVector(rot, Vec3(0.05, -0.02, 0.1));
      Vec3 shift;
      const Vec3 q = bracelet_visible_point(X_WH, width, camera, p, &shift, forearm_H);
      const Vec3 axis = X_WH.R * forearm_H;
      const Vec3 centre = X_WH.p + 0.012 * axis;
      EXPECT_NEAR((q - centre).dot(axis), 0.0, 1e-12);
      EXPECT_NEAR((q - centre).norm(), 0.5 * r, 1e-12);
      EXPECT_NEAR((q - centre - shift).norm(), 0.0, 1e-12);
      EXPECT_LT((camera - q).norm(), (camera - centre).norm());
      // Not where the in-line forearm puts it.
      EXPECT_GT((q - bracelet_visible_point(X_WH, width, camera, p)).norm(), 1e-3);
    }
  }
  // (0, −1, 0), the default, is the in-line forearm.
  const Pose X_WH = Pose::FromRotationVector(Vec3(0.3, -0.2, 1.0), Vec3(0.05, -0.02, 0.1));
  EXPECT_NEAR((bracelet_visible_point(X_WH, width, camera, p, nullptr, Vec3(0, -1, 0)) -
               bracelet_visible_point(X_WH, width, camera, p)).norm(), 0.0, 1e-15);
}

}  // namespace
}  // namespace spidar::registration
