// Where the wrist term expects the bracelet's detected midpoint: the band centre moved toward the
// camera across the forearm (registration_params.hpp). Checked against the geometry of a cylinder
// written out independently: the point lies on the forearm's cross-section through the band
// centre, at the set share of the band's radius from the axis, on the camera's side.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/vision/camera.hpp"
#include "band_near_side_points.hpp"

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

// The detector's midpoint predicted from the band (bracelet_midpoint_px), against the detector's
// rule applied to pixels: the band's near side sampled densely around and along it (written out
// here from the ellipse section), the pixels its points fall in, then OpenCV's moments for the
// centroid and major axis and the pixel centres' extent along it (half a pixel beyond at each end),
// as vision/bracelet.cpp takes them from the red pixels.
TEST(BraceletMidpoint, IsWhereTheDetectorsRulePutsTheBandsPixels) {
  RegistrationParams p;
  const vision::Camera camera = vision::default_rig_camera();
  const double width = 0.083;
  const Vec3 p_W_wrist = camera.X_WC().p + 0.45 * (camera.X_WC().R * Vec3::UnitZ());  // 45 cm ahead
  int checked = 0;
  for (const Vec3& rot : {Vec3(0, 0, 0), Vec3(0.3, -0.2, 1.0), Vec3(-1.2, 0.4, 0.1), Vec3(1.4, 0.2, -0.5)}) {
    for (const Vec3& forearm_H : {Vec3(0, -1, 0), Vec3(0.3, -0.9, 0.3).normalized()}) {
      const Pose X_WH = Pose::FromRotationVector(rot, p_W_wrist);
      const Mat3 R = X_WH.R.toRotationMatrix();
      const Mat3 R_F = hand::wrist_bend(R, R * forearm_H) * R;
      const Pose X_WF{Quat(R_F).normalized(), X_WH.p};
      const auto predicted = bracelet_midpoint_px(X_WF, width, camera, p);
      ASSERT_TRUE(predicted.has_value());
      // The pixels.
      cv::Mat mask(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
      for (const Vec2& uv : testing::band_near_side_points(R_F, X_WH.p, width, camera, p, 60, 2000)) {
        const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
        if (u >= 0 && v >= 0 && u < mask.cols && v < mask.rows) mask.at<std::uint8_t>(v, u) = 255;
      }
      const cv::Moments m = cv::moments(mask, true);
      ASSERT_GT(m.m00, 50.0);
      const Vec2 c(m.m10 / m.m00, m.m01 / m.m00);
      const double angle = 0.5 * std::atan2(2.0 * m.mu11, m.mu20 - m.mu02);
      const Vec2 axis(std::cos(angle), std::sin(angle));
      double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min;
      for (int v = 0; v < mask.rows; ++v)
        for (int u = 0; u < mask.cols; ++u)
          if (mask.at<std::uint8_t>(v, u)) {
            const double t = (Vec2(u, v) - c).dot(axis);
            t_min = std::min(t_min, t);
            t_max = std::max(t_max, t);
          }
      const Vec2 detected = c + 0.5 * ((t_min - 0.5) + (t_max + 0.5)) * axis;
      // Within 1.5 px (0.1–1.1 px measured): the pixels quantise the band's outline.
      EXPECT_LT((*predicted - detected).norm(), 1.5)
          << "rotation " << rot.transpose() << ", forearm " << forearm_H.transpose() << ": predicted "
          << predicted->transpose() << ", from the pixels " << detected.transpose();
      // And not where the band's centre on the forearm's axis projects: the near side is seen.
      EXPECT_GT((*predicted - camera.project(X_WF * Vec3(0, -p.bracelet_offset_m, 0))).norm(), 2.0);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8);
  // A band behind the camera has no midpoint.
  const Pose behind{Quat::Identity(), camera.X_WC().p - 0.3 * (camera.X_WC().R * Vec3::UnitZ())};
  EXPECT_FALSE(bracelet_midpoint_px(behind, width, camera, p).has_value());
}

// With bracelet_detector_midpoint the wrist term's frozen point projects onto the predicted
// midpoint, at the visible point's depth; without, it is bracelet_visible_point.
TEST(BraceletMidpoint, TheWristTermExpectsItWhenAsked) {
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  hand::HandParams q;
  q.set_wrist(camera.X_WC().p + 0.45 * (camera.X_WC().R * Vec3::UnitZ()), Vec3(0.3, -0.2, 1.0));
  HandObservation obs;
  obs.wrist_px = Vec2(320, 240);
  obs.forearm_H = Vec3(0.3, -0.9, 0.3).normalized();
  ImageEvidence image;
  image.camera = &camera;
  for (const bool detector : {false, true}) {
    RegistrationParams p;
    p.bracelet_detector_midpoint = detector;
    const ResidualProblem pr{&model, &obs, &image, nullptr, &p};
    FrozenTargets tg;
    freeze_targets(pr, q, &tg);
    ASSERT_TRUE(tg.wrist_active);
    const Pose X_WH = hand::hand_pose(q);
    const Vec3 centre = X_WH * Vec3(p.bracelet_offset_m * obs.forearm_H);
    const Vec3 expected_point = centre + tg.bracelet_shift_W;
    const Vec3 visible = bracelet_visible_point(X_WH, model.shape.dimensions.width, camera.X_WC().p, p, nullptr,
                                                obs.forearm_H);
    if (!detector) {
      EXPECT_NEAR((expected_point - visible).norm(), 0.0, 1e-12);
      continue;
    }
    const Mat3 R = X_WH.R.toRotationMatrix();
    const Pose X_WF = hand::forearm_pose(X_WH, R * obs.forearm_H);
    const auto m = bracelet_midpoint_px(X_WF, model.shape.dimensions.width, camera, p);
    ASSERT_TRUE(m.has_value());
    EXPECT_NEAR((camera.project(expected_point) - *m).norm(), 0.0, 1e-6);
    EXPECT_NEAR(camera.depth(expected_point), camera.depth(visible), 1e-9);
    EXPECT_GT((camera.project(expected_point) - camera.project(visible)).norm(), 0.5);
  }
}

}  // namespace
}  // namespace spidar::registration
