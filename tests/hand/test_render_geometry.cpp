// Render geometry: capsules along the bones, the palm box, both hands.
#include <gtest/gtest.h>

#include "hand_test_util.hpp"
#include "spidar/hand/render_geometry.hpp"

namespace spidar::hand {
namespace {

TEST(RenderGeometry, CapsulesFollowTheBones) {
  std::mt19937 rng(4);
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    const HandParams q = testing::random_params(m, rng);
    const HandPoints p = forward_kinematics(m, q);
    const HandRenderShapes s = hand_render_shapes(m, q);
    EXPECT_EQ(s.side, side);
    ASSERT_EQ(s.capsules.size(), 19u);
    ASSERT_EQ(s.boxes.size(), 1u);
    int per_finger[kFingerCount] = {};
    for (const Capsule& c : s.capsules) {
      ASSERT_GE(c.finger, 0);
      ASSERT_LT(c.finger, kFingerCount);
      ++per_finger[c.finger];
      EXPECT_GT(c.radius, 0.005);
      EXPECT_LT(c.radius, 0.015);
      const DigitShape& d = m.shape.digits[c.finger];
      EXPECT_EQ(c.radius, d.radius[c.segment]);
      const int last = c.finger == kThumb ? 2 : 3;
      const int k_end = c.finger == kThumb ? c.segment + 1 : c.segment;  // joint at the end
      const Vec3& end = p.p_W_joint[joint_index(c.finger, k_end)];
      if (c.segment < last) {
        EXPECT_LT((c.p_W_b - end).norm(), 1e-15);
        EXPECT_NEAR((c.p_W_b - c.p_W_a).norm(), d.length[c.segment], 1e-12);
      } else {
        // The distal capsule's rounded end reaches the tip.
        EXPECT_NEAR((c.p_W_b - end).norm(), c.radius, 1e-12);
        EXPECT_NEAR((c.p_W_b - c.p_W_a).norm() + c.radius, d.length[c.segment], 1e-12);
      }
    }
    EXPECT_EQ(per_finger[kThumb], 3);
    for (int f = kIndex; f <= kLittle; ++f) EXPECT_EQ(per_finger[f], 4);

    // The palm box lies between the wrist and the MCP joints, oriented with the hand.
    const Box& palm = s.boxes[0];
    const Vec3 p_B_mcp = palm.X_WB.inverse() * p.p_W_joint[joint_index(kMiddle, 0)];
    EXPECT_LE(std::abs(p_B_mcp.x()), palm.half_extents.x());
    EXPECT_GT(p_B_mcp.y(), 0.0);
    EXPECT_LT(p_B_mcp.y(), palm.half_extents.y() + 0.02);
    EXPECT_LT((palm.X_WB.R.toRotationMatrix() - hand_pose(q).R.toRotationMatrix()).norm(), 1e-14);
  }
}

TEST(RenderGeometry, LeftShapesMirrorTheRight) {
  std::mt19937 rng(8);
  const HandModel right = default_hand_model(Side::kRight);
  const HandModel left = default_hand_model(Side::kLeft);
  const Mat3 M = Vec3(-1.0, 1.0, 1.0).asDiagonal();
  const HandParams q = testing::random_params(right, rng);
  const auto r = hand_render_shapes(right, q);
  const auto l = hand_render_shapes(left, mirror_params(q));
  ASSERT_EQ(r.capsules.size(), l.capsules.size());
  for (std::size_t i = 0; i < r.capsules.size(); ++i) {
    EXPECT_LT((l.capsules[i].p_W_a - M * r.capsules[i].p_W_a).norm(), 1e-14);
    EXPECT_LT((l.capsules[i].p_W_b - M * r.capsules[i].p_W_b).norm(), 1e-14);
  }
  EXPECT_LT((l.boxes[0].X_WB.p - M * r.boxes[0].X_WB.p).norm(), 1e-14);
  // Mirrored orientation: R_left = M R_right M.
  const Mat3 Rr = r.boxes[0].X_WB.R.toRotationMatrix();
  const Mat3 Rl = l.boxes[0].X_WB.R.toRotationMatrix();
  EXPECT_LT((Rl - M * Rr * M).norm(), 1e-14);
}

}  // namespace
}  // namespace spidar::hand
