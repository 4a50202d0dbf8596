// Registration metrics on cases worked by hand.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace spidar::registration
