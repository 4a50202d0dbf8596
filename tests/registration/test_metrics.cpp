// Registration metrics on cases worked by hand.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "registration_test_util.hpp"
#include "spidar/registration/metrics.hpp"

namespace spidar::registration {
namespace {

TEST(Metrics, MaskIou) {
  cv::Mat a = cv::Mat::zeros(10, 10, CV_8UC1), b = cv::Mat::zeros(10, 10, CV_8UC1);
  EXPECT_EQ(mask_iou(a, b), 1.0);
  a.rowRange(0, 4).setTo(255);  // 40 px
  b.rowRange(2, 6).setTo(1);    // 40 px, 20 shared
  EXPECT_DOUBLE_EQ(mask_iou(a, b), 20.0 / 60.0);
  EXPECT_THROW(mask_iou(a, cv::Mat::zeros(5, 5, CV_8UC1)), SpidarError);
}

TEST(Metrics, JointAndFingertipErrors) {
  const auto models = test::model_hands();
  const auto q = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandPoints truth = hand::forward_kinematics(models[1], q[1]);
  EXPECT_EQ(joint_px_error(truth, truth, camera), 0.0);
  EXPECT_EQ(fingertip_error_m(truth, truth), 0.0);
  hand::HandPoints moved = truth;
  for (auto& p : moved.p_W_fingertip) p += Vec3(0.003, 0.0, 0.004);
  EXPECT_NEAR(fingertip_error_m(moved, truth), 0.005, 1e-12);
  // Shift every joint along the camera's x axis by 1 mm: about f/z px each.
  const Vec3 x_C = camera.X_WC().R.toRotationMatrix().col(0);
  double expected = 0;
  for (auto& p : moved.p_W_joint) {
    expected += (camera.project(p + 0.001 * x_C) - camera.project(p)).norm();
    p += 0.001 * x_C;
  }
  EXPECT_NEAR(joint_px_error(moved, truth, camera), expected / hand::kJointCount, 1e-9);
  // Joints behind the camera are skipped.
  moved = truth;
  moved.p_W_joint[0] = camera.X_WC().p - 0.1 * camera.X_WC().R.toRotationMatrix().col(2);
  EXPECT_EQ(joint_px_error(moved, truth, camera), 0.0);
}

/// The rotation vector [rad] of a rotation matrix.
Vec3 rotation_vector(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

TEST(Metrics, PalmRotationErrorIsInTheHandsOwnAxes) {
  const auto q = test::reaching_hands();
  const hand::HandParams& truth = q[1];
  const Mat3 R_t = hand::hand_pose(truth).R.toRotationMatrix();
  EXPECT_LT(palm_rotation_error_rad(truth, truth, hand::Side::kRight).norm(), 1e-12);
  // The fit turned by 0.2 rad about each of the true hand's own axes in turn.
  for (int axis = 0; axis < 3; ++axis) {
    hand::HandParams fit = truth;
    const Vec3 a = Vec3::Unit(axis);
    fit.q.segment<3>(hand::kWristRotX) = rotation_vector(R_t * Eigen::AngleAxisd(0.2, a).toRotationMatrix());
    EXPECT_TRUE(palm_rotation_error_rad(fit, truth, hand::Side::kRight).isApprox(0.2 * a, 1e-9))
        << axis << ": " << palm_rotation_error_rad(fit, truth, hand::Side::kRight).transpose();
  }
}

TEST(Metrics, APalmRotationErrorAndItsMirrorImageAreTheSame) {
  const auto models = test::model_hands();
  const auto q = test::reaching_hands();
  // A right hand's truth and a fit turned off it about some axis.
  const hand::HandParams& truth = q[1];
  hand::HandParams fit = truth;
  fit.q.segment<3>(hand::kWristRotX) = rotation_vector(
      hand::hand_pose(truth).R.toRotationMatrix() * Eigen::AngleAxisd(0.3, Vec3(0.2, -0.5, 0.8).normalized()).toRotationMatrix());
  fit.q.segment<3>(hand::kWristX) += Vec3(0.01, -0.02, 0.005);
  // Both mirrored through the world's x = 0 plane into left hands: S p for the wrist, and
  // S R S = exp([−S r]×) for the rotation (S = diag(−1, 1, 1)); the fingers' angles stay.
  const auto mirrored = [](const hand::HandParams& right) {
    hand::HandParams left = right;
    left.q[hand::kWristX] = -right.q[hand::kWristX];
    left.q[hand::kWristRotY] = -right.q[hand::kWristRotY];
    left.q[hand::kWristRotZ] = -right.q[hand::kWristRotZ];
    return left;
  };
  const hand::HandParams truth_left = mirrored(truth), fit_left = mirrored(fit);
  // The mirror is right: the left hand's joints are the right hand's mirrored.
  const hand::HandPoints right_points = hand::forward_kinematics(models[1], fit);
  const hand::HandPoints left_points = hand::forward_kinematics(models[0], fit_left);
  for (int j = 0; j < hand::kJointCount; ++j) {
    const Vec3 p = right_points.p_W_joint[j];
    ASSERT_TRUE(left_points.p_W_joint[j].isApprox(Vec3(-p.x(), p.y(), p.z()), 1e-9)) << "joint " << j;
  }
  const Vec3 right = palm_rotation_error_rad(fit, truth, hand::Side::kRight);
  const Vec3 left = palm_rotation_error_rad(fit_left, truth_left, hand::Side::kLeft);
  EXPECT_NEAR(right.norm(), 0.3, 1e-9);
  EXPECT_TRUE(left.isApprox(right, 1e-9)) << left.transpose() << " vs " << right.transpose();
}

}  // namespace
}  // namespace spidar::registration
