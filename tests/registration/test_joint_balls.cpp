// Joint-ball targets (eq. 21) on hand-made mattes, and which joints get a ball.
#include <gtest/gtest.h>

#include "registration_test_util.hpp"
#include "spidar/registration/joint_balls.hpp"

namespace spidar::registration {
namespace {

cv::Mat half_plane(int x_edge) {  // hand left of x_edge (columns < x_edge)
  cv::Mat a = cv::Mat::zeros(100, 200, CV_32FC1);
  a.colRange(0, x_edge).setTo(1.0f);
  return a;
}

TEST(JointBall, InsideTheSilhouetteStays) {
  const cv::Mat alpha = half_plane(200);
  int on = -1;
  const Vec2 t = joint_ball_target(alpha, Vec2(50, 50), Vec2(0, 1), 6.0, 0.5, 0.5, &on);
  EXPECT_EQ(on, 4);
  EXPECT_NEAR((t - Vec2(50, 50)).norm(), 0.0, 1e-12);
}

TEST(JointBall, NearTheEdgeIsPushedBackInside) {
  // Bone along +y at x = 97, radius 6: the across neighbour at x = 103 is off the silhouette
  // (edge at 100), the other three are on. P̃ = P + α (−6, 0).
  const cv::Mat alpha = half_plane(100);
  int on = -1;
  const Vec2 t = joint_ball_target(alpha, Vec2(97, 50), Vec2(0, 1), 6.0, 0.5, 0.5, &on);
  EXPECT_EQ(on, 3);
  EXPECT_NEAR(t.x(), 97 - 0.5 * 6.0, 1e-12);
  EXPECT_NEAR(t.y(), 50.0, 1e-12);
  // A bone pointing at the edge: the along neighbour is off, so the joint moves back along it.
  const Vec2 u = joint_ball_target(alpha, Vec2(97, 50), Vec2(1, 0), 6.0, 1.0, 0.5, &on);
  EXPECT_EQ(on, 3);
  EXPECT_NEAR(u.x(), 91.0, 1e-12);
}

TEST(JointBall, WhollyOutsideGivesNoEvidence) {
  const cv::Mat alpha = half_plane(10);
  int on = -1;
  const Vec2 t = joint_ball_target(alpha, Vec2(150, 50), Vec2::Zero(), 6.0, 0.5, 0.5, &on);
  EXPECT_EQ(on, 0);
  EXPECT_EQ(t, Vec2(150, 50));
}

TEST(JointBall, BallsAtMcpPipDipNotAtWristOrTips) {
  const auto models = test::model_hands();
  const auto q = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  cv::Mat mask;
  test::draw_capsule_mask(models[1], q[1], camera, &mask);
  cv::Mat alpha;
  mask.convertTo(alpha, CV_32FC1, 1.0 / 255.0);
  const hand::HandPoints pts = hand::forward_kinematics(models[1], q[1]);
  JointBalls balls;
  joint_ball_targets(models[1], pts, camera, alpha, RegistrationParams{}, &balls);
  EXPECT_FALSE(balls[hand::kWristJoint].used);
  int inside = 0;
  for (int f = 0; f < hand::kFingerCount; ++f) {
    EXPECT_FALSE(balls[hand::joint_index(f, 3)].used) << hand::joint_name(hand::joint_index(f, 3));
    for (int k = 0; k < 3; ++k) {
      const int j = hand::joint_index(f, k);
      const JointBall& b = balls[j];
      ASSERT_TRUE(b.used) << hand::joint_name(j);
      EXPECT_NEAR((b.centre_px - camera.project(pts.p_W_joint[j])).norm(), 0.0, 1e-9);
      const int seg = f == hand::kThumb ? k : k + 1;
      EXPECT_NEAR(b.radius_px,
                  models[1].shape.digits[f].radius[seg] * camera.intrinsics().fx /
                      camera.depth(pts.p_W_joint[j]),
                  1e-9);
      EXPECT_GT(b.radius_px, 2.0);
      // The model's own silhouette: every ball is on it, most of them wholly.
      EXPECT_GE(b.on_count, 2) << hand::joint_name(j);
      if (b.on_count == 4) ++inside;
    }
  }
  EXPECT_GE(inside, 8);
  // Without a matte there are no balls.
  joint_ball_targets(models[1], pts, camera, cv::Mat(), RegistrationParams{}, &balls);
  for (const auto& b : balls) EXPECT_FALSE(b.used);
}

}  // namespace
}  // namespace spidar::registration
