// Forward kinematics: zero-pose geometry, bone lengths, coupling, mirror symmetry, wrist pose.
#include <gtest/gtest.h>

#include <cmath>

#include "hand_test_util.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {
namespace {

using testing::random_params;
using units::deg_to_rad;

const Mat3 kMirrorX = Vec3(-1.0, 1.0, 1.0).asDiagonal();

// The point before `k` on a digit's chain (k ≥ 1).
Vec3 bone_vector(const HandPoints& p, int f, int k) {
  return p.p_W_joint[joint_index(f, k)] - p.p_W_joint[joint_index(f, k - 1)];
}

double angle_between(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(Kinematics, ZeroPoseOfTheRightHand) {
  const HandModel m = default_hand_model(Side::kRight);
  const HandPoints p = forward_kinematics(m, HandParams{});
  EXPECT_EQ(p.p_W_joint[kWristJoint], Vec3::Zero());
  // Fingers straight in the palm plane z = 0, along their metacarpals, pointing away from the
  // user (+y); the thumb on the user's left (−x), the little finger on the right (+x).
  for (int f = kIndex; f <= kLittle; ++f) {
    const Vec3 dir = m.shape.digits[f].R_H_digit.col(1);
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(p.p_W_joint[joint_index(f, k)].z(), 0.0, 1e-15);
      if (k > 0) {
        EXPECT_LT((bone_vector(p, f, k).normalized() - dir).norm(), 1e-12);
      }
    }
    EXPECT_GT(p.p_W_joint[joint_index(f, 3)].y(), 0.12);
  }
  EXPECT_NEAR(p.p_W_joint[joint_index(kMiddle, 3)].y(), 0.19, 1e-12);
  EXPECT_LT(p.p_W_joint[joint_index(kThumb, 3)].x(), p.p_W_joint[joint_index(kIndex, 3)].x());
  EXPECT_LT(p.p_W_joint[joint_index(kThumb, 3)].x(), -0.04);
  EXPECT_GT(p.p_W_joint[joint_index(kLittle, 3)].x(), p.p_W_joint[joint_index(kRing, 3)].x());
  // Middle is the longest finger; the fingertip caps sit 8 mm back from the bone ends.
  for (int f = kThumb; f <= kRing; ++f) {
    EXPECT_NEAR((p.p_W_fingertip[f] - p.p_W_joint[joint_index(f, 3)]).norm(), 0.008, 1e-12);
    EXPECT_LT(p.p_W_fingertip[f].y(), p.p_W_joint[joint_index(f, 3)].y());
  }
  // The thumb points forward and to the radial side, below the palm plane.
  const Vec3 thumb = p.p_W_joint[joint_index(kThumb, 3)] - p.p_W_joint[joint_index(kThumb, 0)];
  EXPECT_GT(thumb.y(), 0.0);
  EXPECT_LT(thumb.x(), 0.0);
}

TEST(Kinematics, LeftZeroPoseMirrorsTheRight) {
  const HandPoints r = forward_kinematics(default_hand_model(Side::kRight), HandParams{});
  const HandPoints l = forward_kinematics(default_hand_model(Side::kLeft), HandParams{});
  for (int j = 0; j < kJointCount; ++j) {
    EXPECT_LT((l.p_W_joint[j] - kMirrorX * r.p_W_joint[j]).norm(), 1e-15) << joint_name(j);
  }
  // Left thumb on the user's right of the left index finger.
  EXPECT_GT(l.p_W_joint[joint_index(kThumb, 3)].x(), l.p_W_joint[joint_index(kIndex, 3)].x());
}

TEST(Kinematics, MirroredParametersGiveTheMirrorImage) {
  std::mt19937 rng(11);
  for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
    const HandModel right = default_hand_model(Side::kRight, coupling);
    const HandModel left = default_hand_model(Side::kLeft, coupling);
    for (int n = 0; n < 100; ++n) {
      const HandParams q = random_params(right, rng);
      const HandPoints r = forward_kinematics(right, q);
      const HandPoints l = forward_kinematics(left, mirror_params(q));
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_LT((l.p_W_joint[j] - kMirrorX * r.p_W_joint[j]).norm(), 1e-14);
      }
      for (int f = 0; f < kFingertipCount; ++f) {
        EXPECT_LT((l.p_W_fingertip[f] - kMirrorX * r.p_W_fingertip[f]).norm(), 1e-14);
      }
    }
  }
}

TEST(Kinematics, BoneLengthsArePreserved) {
  std::mt19937 rng(7);
  const HandShape& s = default_hand_shape();
  for (auto side : {Side::kLeft, Side::kRight}) {
    for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
      const HandModel m = default_hand_model(side, coupling);
      for (int n = 0; n < 100; ++n) {
        const HandPoints p = forward_kinematics(m, random_params(m, rng));
        // Thumb: metacarpal, proximal, distal; fingers: proximal, middle, distal.
        for (int f = 0; f < kFingerCount; ++f) {
          const int first = f == kThumb ? 0 : 1;
          for (int k = 1; k < 4; ++k) {
            EXPECT_NEAR(bone_vector(p, f, k).norm(), s.digits[f].length[first + k - 1], 1e-12);
          }
        }
        // MCPs are rigid with the wrist (the palm does not deform).
        for (int f = kIndex; f <= kLittle; ++f) {
          EXPECT_NEAR((p.p_W_joint[joint_index(f, 0)] - p.p_W_joint[kWristJoint]).norm(),
                      s.digits[f].p_H_mcp.norm(), 1e-12);
        }
        for (int f = 0; f < kFingertipCount; ++f) {
          EXPECT_NEAR((p.p_W_fingertip[f] - p.p_W_joint[joint_index(f, 3)]).norm(), 0.008, 1e-12);
        }
      }
    }
  }
}

TEST(Kinematics, CoupledJointAnglesFollowTheCoupling) {
  std::mt19937 rng(3);
  for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
    const HandModel m = default_hand_model(Side::kRight, coupling);
    for (int n = 0; n < 50; ++n) {
      HandParams q = random_params(m, rng);
      // Keep the coupled penultimate angle positive, so the unsigned bone angle is the joint's.
      for (int f = kThumb; f <= kLittle; ++f) {
        const int d = digit_params(f).distal;
        q.q[d] = std::max(q.q[d], 0.3);
      }
      const HandPoints p = forward_kinematics(m, q);
      for (int f = kThumb; f <= kLittle; ++f) {
        const auto cols = digit_params(f);
        const double distal = q.q[cols.distal];
        const double penultimate = couple(coupling, distal).penultimate;
        EXPECT_NEAR(angle_between(bone_vector(p, f, 2), bone_vector(p, f, 3)), distal, 1e-10);
        EXPECT_NEAR(angle_between(bone_vector(p, f, 1), bone_vector(p, f, 2)), penultimate, 1e-10);
        if (f != kThumb) {
          // The MCP flexion is the angle out of the palm plane (the plane's normal is z_H).
          const Mat3 R_WH = hand_pose(q).R.toRotationMatrix();
          const Vec3 prox = R_WH.transpose() * bone_vector(p, f, 1).normalized();
          EXPECT_NEAR(std::asin(-prox.z()), q.q[cols.flexion], 1e-10);
        }
      }
    }
  }
}

TEST(Kinematics, FlexionCurlsTowardThePalmAndAbductionSpreads) {
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    const HandPoints zero = forward_kinematics(m, HandParams{});
    const double sx = side == Side::kRight ? 1.0 : -1.0;  // toward the little finger
    HandParams q;
    q[kIndexMcpFlexion] = deg_to_rad(60);
    q[kMiddleDip] = deg_to_rad(40);
    q[kRingMcpFlexion] = deg_to_rad(30);
    q[kThumbIp] = deg_to_rad(40);
    const HandPoints p = forward_kinematics(m, q);
    EXPECT_LT(p.p_W_joint[joint_index(kIndex, 3)].z(), -0.05);
    EXPECT_LT(p.p_W_joint[joint_index(kMiddle, 3)].z(), -0.02);
    // The little finger copies the ring finger's flexion.
    EXPECT_LT(p.p_W_joint[joint_index(kLittle, 3)].z(), -0.02);
    EXPECT_NEAR(angle_between(bone_vector(p, kLittle, 1), bone_vector(zero, kLittle, 1)),
                deg_to_rad(30), 1e-12);
    // Thumb flexion curls it toward the palm side.
    EXPECT_LT(p.p_W_joint[joint_index(kThumb, 3)].z(), zero.p_W_joint[joint_index(kThumb, 3)].z());

    HandParams a;
    a[kIndexMcpAbduction] = deg_to_rad(15);
    a[kRingMcpAbduction] = deg_to_rad(15);
    const HandPoints s = forward_kinematics(m, a);
    const auto dx = [&](int f) {
      return sx * (s.p_W_joint[joint_index(f, 3)] - zero.p_W_joint[joint_index(f, 3)]).x();
    };
    EXPECT_LT(dx(kIndex), -0.01);  // toward the thumb
    EXPECT_GT(dx(kRing), 0.01);    // toward the little finger
    EXPECT_GT(dx(kLittle), 0.01);  // copies the ring
    EXPECT_NEAR(dx(kMiddle), 0.0, 1e-15);

    // CMC abduction takes the thumb away from the palm (palmar, −z); CMC flexion across it.
    HandParams t;
    t[kThumbCmcAbduction] = deg_to_rad(45);
    EXPECT_LT(forward_kinematics(m, t).p_W_joint[joint_index(kThumb, 3)].z(),
              zero.p_W_joint[joint_index(kThumb, 3)].z() - 0.02);
    t = HandParams{};
    t[kThumbCmcFlexion] = deg_to_rad(30);
    EXPECT_GT(sx * forward_kinematics(m, t).p_W_joint[joint_index(kThumb, 3)].x(),
              sx * zero.p_W_joint[joint_index(kThumb, 3)].x() + 0.02);
  }
}

TEST(Kinematics, ThumbCanOpposeTheIndexFinger) {
  // A pinch must be reachable within the limits: some pose brings the thumb and index caps
  // within 2 cm (cap centres; the finger pads touch before that).
  const HandModel m = default_hand_model(Side::kRight);
  double best = 1e9;
  const int n = 6;
  auto lerp = [&](int p, int i) {
    return m.limits.lower[p] + (m.limits.upper[p] - m.limits.lower[p]) * i / (n - 1);
  };
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int c = 0; c < n; ++c)
        for (int d = 0; d < n; ++d)
          for (int e = 0; e < n; ++e) {
            HandParams q;
            q[kThumbCmcFlexion] = lerp(kThumbCmcFlexion, a);
            q[kThumbCmcAbduction] = lerp(kThumbCmcAbduction, b);
            q[kThumbIp] = lerp(kThumbIp, c);
            q[kIndexMcpFlexion] = lerp(kIndexMcpFlexion, d);
            q[kIndexDip] = lerp(kIndexDip, e);
            const HandPoints p = forward_kinematics(m, q);
            best = std::min(best, (p.p_W_fingertip[kThumb] - p.p_W_fingertip[kIndex]).norm());
          }
  EXPECT_LT(best, 0.02);
}

TEST(Kinematics, WristPoseMovesTheHandRigidly) {
  std::mt19937 rng(5);
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    for (int n = 0; n < 50; ++n) {
      HandParams q = random_params(m, rng);
      HandParams local = q;
      local.set_wrist(Vec3::Zero(), Vec3::Zero());
      const Pose X_WH = hand_pose(q);
      const HandPoints p = forward_kinematics(m, q);
      const HandPoints pl = forward_kinematics(m, local);
      for (int j = 0; j < kJointCount; ++j) {
        EXPECT_LT((p.p_W_joint[j] - X_WH * pl.p_W_joint[j]).norm(), 1e-14);
      }
      EXPECT_LT((X_WH.R.toRotationMatrix() - rotation_from_vector(q.r_W_hand())).norm(), 1e-14);
      // Matches core's rotation-vector convention.
      const Pose core_pose = Pose::FromRotationVector(q.r_W_hand(), q.p_W_wrist());
      EXPECT_LT((core_pose.R.toRotationMatrix() - X_WH.R.toRotationMatrix()).norm(), 1e-14);
    }
  }
}

TEST(Kinematics, PointsOnlyAndWithJacobiansAgree) {
  std::mt19937 rng(9);
  const HandModel m = default_hand_model(Side::kLeft);
  for (int n = 0; n < 20; ++n) {
    const HandParams q = random_params(m, rng);
    const HandPoints a = forward_kinematics(m, q);
    HandPoints b;
    FingertipJacobian Jt;
    JointJacobian Jj;
    forward_kinematics(m, q, &b, &Jt, &Jj);
    for (int j = 0; j < kJointCount; ++j) EXPECT_EQ(a.p_W_joint[j], b.p_W_joint[j]);
    for (int f = 0; f < kFingertipCount; ++f) EXPECT_EQ(a.p_W_fingertip[f], b.p_W_fingertip[f]);
  }
}

}  // namespace
}  // namespace spidar::hand
