// Analytic Jacobians against central finite differences (3D fingertips, 3D joints, 2D joints).
#include <gtest/gtest.h>

#include <ostream>

#include "hand_test_util.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/projection.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {

// Readable test parameters in gtest output.
void PrintTo(Side side, std::ostream* os) {
  *os << (side == Side::kLeft ? "left" : "right");
}
void PrintTo(Coupling coupling, std::ostream* os) {
  *os << coupling_name(coupling);
}

namespace {

using testing::central_differences;
using testing::random_params;
using testing::relative_error;

constexpr double kTolerance = 1e-6;  // relative

using TipVec = Eigen::Matrix<double, 3 * kFingertipCount, 1>;
using JointVec = Eigen::Matrix<double, 3 * kJointCount, 1>;
using UvVec = Eigen::Matrix<double, 2 * kJointCount, 1>;

TipVec stacked_tips(const HandModel& m, const HandParams& q) {
  const HandPoints p = forward_kinematics(m, q);
  TipVec v;
  for (int f = 0; f < kFingertipCount; ++f) v.segment<3>(3 * f) = p.p_W_fingertip[f];
  return v;
}

JointVec stacked_joints(const HandModel& m, const HandParams& q) {
  const HandPoints p = forward_kinematics(m, q);
  JointVec v;
  for (int j = 0; j < kJointCount; ++j) v.segment<3>(3 * j) = p.p_W_joint[j];
  return v;
}

// Checks both 3D Jacobians at q against central differences.
void check_3d(const HandModel& m, const HandParams& q) {
  HandPoints p;
  FingertipJacobian Jt;
  JointJacobian Jj;
  forward_kinematics(m, q, &p, &Jt, &Jj);
  const auto Jt_fd = central_differences<3 * kFingertipCount>(
      q, [&](const HandParams& x) { return stacked_tips(m, x); });
  const auto Jj_fd = central_differences<3 * kJointCount>(
      q, [&](const HandParams& x) { return stacked_joints(m, x); });
  EXPECT_LT(relative_error(Jt, Jt_fd), kTolerance) << "fingertips at q = " << q.q.transpose();
  EXPECT_LT(relative_error(Jj, Jj_fd), kTolerance) << "joints at q = " << q.q.transpose();
  // Column by column as well, so that small columns (e.g. abduction) are checked on their scale.
  for (int i = 0; i < kParamCount; ++i) {
    EXPECT_LT(relative_error(Jt.col(i), Jt_fd.col(i), 1e-2), kTolerance) << param_name(i);
    EXPECT_LT(relative_error(Jj.col(i), Jj_fd.col(i), 1e-2), kTolerance) << param_name(i);
  }
}

class JacobianTest : public ::testing::TestWithParam<std::tuple<Side, Coupling>> {};

TEST_P(JacobianTest, ThreeDMatchesCentralDifferencesOverRandomPoses) {
  const auto [side, coupling] = GetParam();
  const HandModel m = default_hand_model(side, coupling);
  std::mt19937 rng(1234 + 10 * static_cast<int>(side) + static_cast<int>(coupling));
  for (int n = 0; n < 200; ++n) check_3d(m, random_params(m, rng));
}

TEST_P(JacobianTest, WristRotationNearZeroAndNearPi) {
  const auto [side, coupling] = GetParam();
  const HandModel m = default_hand_model(side, coupling);
  std::mt19937 rng(77);
  for (double angle : {0.0, 1e-9, 1e-5, 9.9e-3, 1.01e-2, 0.5, 3.0, 3.1}) {
    HandParams q = random_params(m, rng);
    q.set_wrist(q.p_W_wrist(), Vec3(0.3, -0.5, 0.8).normalized() * angle);
    check_3d(m, q);
  }
}

TEST_P(JacobianTest, UserProfileAndLimitPoses) {
  const auto [side, coupling] = GetParam();
  HandDimensions dims{0.1976, 0.0825, Vec3(0.001, -0.009, 0.002)};
  const HandModel m = make_hand_model(side, dims, coupling).value();
  HandParams lo;
  HandParams hi;
  for (int i = kThumbCmcFlexion; i < kParamCount; ++i) {
    lo.q[i] = m.limits.lower[i];
    hi.q[i] = m.limits.upper[i];
  }
  check_3d(m, HandParams{});
  check_3d(m, lo);
  check_3d(m, hi);
}

// A pinhole camera above the frame looking down at 50° (as in the paper), f = 600 px.
struct TestCamera {
  Mat3 R_CW;
  Vec3 p_C_Wo;
  double f = 600.0;
  Vec2 c{320.0, 240.0};

  TestCamera() {
    // Camera at (0, −0.35, 0.45), z_C toward the frame centre, x_C along world x.
    const Vec3 p_W_C(0.0, -0.35, 0.45);
    const Vec3 z = (-p_W_C).normalized();
    const Vec3 x = Vec3::UnitX();
    const Vec3 y = z.cross(x);
    R_CW.row(0) = x;
    R_CW.row(1) = y;
    R_CW.row(2) = z;
    p_C_Wo = -R_CW * p_W_C;
  }
  Vec2 project(const Vec3& p_W) const {
    const Vec3 p = R_CW * p_W + p_C_Wo;
    return c + f * p.head<2>() / p.z();
  }
  ProjectionJacobian jacobian(const Vec3& p_W) const {
    const Vec3 p = R_CW * p_W + p_C_Wo;
    ProjectionJacobian J;
    J << f / p.z(), 0.0, -f * p.x() / (p.z() * p.z()),  //
        0.0, f / p.z(), -f * p.y() / (p.z() * p.z());
    return J * R_CW;
  }
};

TEST_P(JacobianTest, ProjectedJointsMatchCentralDifferences) {
  const auto [side, coupling] = GetParam();
  const HandModel m = default_hand_model(side, coupling);
  const TestCamera cam;
  const FunctionProjection projection([&](const Vec3& p) { return cam.project(p); },
                                      [&](const Vec3& p) { return cam.jacobian(p); });
  // The test camera's own Jacobian first.
  const Vec3 p0(0.02, 0.05, 0.03);
  ProjectionJacobian J_fd;
  for (int i = 0; i < 3; ++i) {
    Vec3 d = Vec3::Zero();
    d[i] = 1e-6;
    J_fd.col(i) = (cam.project(p0 + d) - cam.project(p0 - d)) / 2e-6;
  }
  ASSERT_LT(relative_error(cam.jacobian(p0), J_fd), 1e-7);

  std::mt19937 rng(99);
  for (int n = 0; n < 100; ++n) {
    // Hands near the frame centre, moderately turned, so the camera sees them.
    HandParams q = random_params(m, rng, 1.0);
    q.set_wrist(0.3 * q.p_W_wrist(), q.r_W_hand());
    std::array<Vec2, kJointCount> uv;
    ProjectedJointJacobian J;
    projected_joints(m, q, projection, &uv, &J);
    const auto J_ref = central_differences<2 * kJointCount>(q, [&](const HandParams& x) {
      const HandPoints p = forward_kinematics(m, x);
      UvVec v;
      for (int j = 0; j < kJointCount; ++j) v.segment<2>(2 * j) = cam.project(p.p_W_joint[j]);
      return v;
    });
    EXPECT_LT(relative_error(J, J_ref), kTolerance);
    const HandPoints p = forward_kinematics(m, q);
    for (int j = 0; j < kJointCount; ++j) {
      EXPECT_LT((uv[j] - cam.project(p.p_W_joint[j])).norm(), 1e-12);
    }

    // Fingertips through the generic function.
    FingertipJacobian Jt;
    HandPoints pts;
    forward_kinematics(m, q, &pts, &Jt, nullptr);
    std::array<Vec2, kFingertipCount> uv_tip;
    ProjectedFingertipJacobian J_tip;
    project_fingertips(projection, pts, Jt, &uv_tip, &J_tip);
    const auto J_tip_ref = central_differences<2 * kFingertipCount>(q, [&](const HandParams& x) {
      const HandPoints px = forward_kinematics(m, x);
      Eigen::Matrix<double, 2 * kFingertipCount, 1> v;
      for (int f = 0; f < kFingertipCount; ++f) {
        v.segment<2>(2 * f) = cam.project(px.p_W_fingertip[f]);
      }
      return v;
    });
    EXPECT_LT(relative_error(J_tip, J_tip_ref), kTolerance);
  }
}

INSTANTIATE_TEST_SUITE_P(
    HandsAndCouplings, JacobianTest,
    ::testing::Combine(::testing::Values(Side::kLeft, Side::kRight),
                       ::testing::Values(Coupling::kPaperQuadratic, Coupling::kLinear)),
    [](const auto& test_info) {
      return std::string(std::get<0>(test_info.param) == Side::kLeft ? "Left" : "Right") +
             (std::get<1>(test_info.param) == Coupling::kLinear ? "Linear" : "Quadratic");
    });

TEST(JacobianStructure, DigitsDependOnlyOnTheirParameters) {
  const HandModel m = default_hand_model(Side::kRight);
  std::mt19937 rng(2);
  const HandParams q = random_params(m, rng);
  FingertipJacobian Jt;
  JointJacobian Jj;
  forward_kinematics(m, q, nullptr, &Jt, &Jj);
  // The wrist joint moves with the wrist translation only.
  EXPECT_EQ((Jj.block<3, 3>(0, kWristX)), Mat3::Identity());
  EXPECT_TRUE((Jj.block<3, kParamCount - 3>(0, 3).isZero(0.0)));
  for (int f = 0; f < kFingerCount; ++f) {
    const auto cols = digit_params(f);
    for (int i = kThumbCmcFlexion; i < kParamCount; ++i) {
      const bool own = i == cols.flexion || i == cols.abduction || i == cols.distal;
      for (int k = 0; k < 4; ++k) {
        const auto block = Jj.block<3, 1>(3 * joint_index(f, k), i);
        if (!own || k == 0) {
          EXPECT_TRUE(block.isZero(0.0)) << joint_name(joint_index(f, k));
        }
      }
      if (f < kFingertipCount && !own) {
        EXPECT_TRUE((Jt.block<3, 1>(3 * f, i).isZero(0.0)));
      }
    }
  }
  // The coupled (distal) parameter moves the DIP through the PIP angle and the tip through both;
  // the PIP point itself does not depend on it.
  EXPECT_TRUE((Jj.block<3, 1>(3 * joint_index(kIndex, 1), kIndexDip).isZero(0.0)));
  EXPECT_FALSE((Jj.block<3, 1>(3 * joint_index(kIndex, 3), kIndexDip).isZero(1e-9)));
}

TEST(RotationVector, ExpAndLeftJacobian) {
  for (const Vec3& r : {Vec3(0, 0, 0), Vec3(1e-7, 0, 0), Vec3(0.3, -0.2, 0.9), Vec3(0, 0, 3.1),
                        Vec3(0.005, 0.004, -0.003)}) {
    const Mat3 R = rotation_from_vector(r);
    const Mat3 R_ref = r.norm() > 0 ? Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix()
                                    : Mat3::Identity();
    EXPECT_LT((R - R_ref).norm(), 1e-14);
    // exp(r + δ) ≈ exp([J_l δ]×) exp(r) to second order.
    const Mat3 Jl = so3_left_jacobian(r);
    const Vec3 delta(1e-7, -2e-7, 1.5e-7);
    const Mat3 lhs = rotation_from_vector(r + delta);
    const Mat3 rhs = rotation_from_vector(Jl * delta) * R;
    EXPECT_LT((lhs - rhs).norm(), 1e-13);
  }
  EXPECT_EQ(skew(Vec3(1, 2, 3)) * Vec3(4, 5, 6), Vec3(1, 2, 3).cross(Vec3(4, 5, 6)));
}

}  // namespace
}  // namespace spidar::hand

namespace spidar::hand {
namespace {

// A little finger of its own: its joints follow q[17..19], not the ring's parameters; the
// Jacobians' columns for them (and the ring's, which no longer move it) match central differences.
TEST(JacobianStructure, IndependentLittleFingerMatchesCentralDifferences) {
  std::mt19937 rng(7);
  for (auto side : {Side::kLeft, Side::kRight}) {
    const HandModel m = default_hand_model(side);
    for (int trial = 0; trial < 5; ++trial) {
      HandParams q = testing::random_params(m, rng);
      q.little_independent = true;
      q.set_little(Vec3(0.9, -0.1, 0.4));
      check_3d(m, q);
      JointJacobian Jj;
      forward_kinematics(m, q, nullptr, nullptr, &Jj);
      for (int k = 1; k < 4; ++k) {
        const int row = 3 * joint_index(kLittle, k);
        EXPECT_TRUE((Jj.block<3, 3>(row, kRingMcpFlexion).isZero(0.0))) << "little joint " << k;
        EXPECT_FALSE((Jj.block<3, 1>(row, kLittleMcpFlexion).isZero(1e-9))) << "little joint " << k;
      }
      HandParams copy = q;
      copy.little_independent = false;
      const HandPoints a = forward_kinematics(m, q);
      const HandPoints b = forward_kinematics(m, copy);
      double little_moved = 0;
      for (int j = 0; j < kJointCount; ++j) {
        const double d = (a.p_W_joint[j] - b.p_W_joint[j]).norm();
        if (j >= joint_index(kLittle, 1)) {
          little_moved = std::max(little_moved, d);
        } else {
          EXPECT_EQ(d, 0.0) << joint_name(j);
        }
      }
      EXPECT_GT(little_moved, 1e-3);
    }
  }
}

}  // namespace
}  // namespace spidar::hand
