// The user's fingertip stiffness from their hand (sim::finger_holds), checked against the
// fingertip motions of the digits' joints taken by forward kinematics.
#include <gtest/gtest.h>

#include "source_path.hpp"

#include <array>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/sim/finger_hold.hpp"

namespace spidar::sim {
namespace {

hand::HandModel user_right() {
  const auto profiles = hand::load_hand_profiles(spidar::test::source("configs/hands.yaml"));
  return profiles.find("user")->model(hand::Side::kRight);
}

/// Every finger joint in the middle of its range, the wrist somewhere in the workspace.
hand::HandParams mid_range(const hand::HandModel& m) {
  hand::HandParams q;
  q.set_wrist(Vec3(0.02, -0.05, 0.1), Vec3(0.3, -0.2, 0.5));
  for (int p = hand::kThumbCmcFlexion; p < hand::kParamCount; ++p)
    q[p] = 0.5 * (m.limits.lower[p] + m.limits.upper[p]);
  return q;
}

/// Fingertip f's motion per radian of parameter `param` (forward difference of the kinematics).
Vec3 tip_motion(const hand::HandModel& m, const hand::HandParams& q, int f, int param) {
  constexpr double kStep = 1e-7;
  hand::HandParams moved = q;
  moved[param] += kStep;
  return (hand::forward_kinematics(m, moved).p_W_fingertip[f] - hand::forward_kinematics(m, q).p_W_fingertip[f]) / kStep;
}

/// The hold's compliance relative to its softest direction: R·diag(1/scale)·Rᵀ.
Mat3 compliance(const device::FingertipHold& h) {
  return h.R_WE * h.scale.cwiseInverse().asDiagonal() * h.R_WE.transpose();
}

TEST(FingerHold, AwayFromTheLimitsTheFingertipYieldsAsItsJointsMoveIt) {
  const hand::HandModel m = user_right();
  const hand::HandParams q = mid_range(m);
  const auto holds = finger_holds(m, q);
  // Three joints each, well spread mid-range: no axis clamped at kMaxHoldScale (the thumb's
  // fingertip hardly moves along its own axis, so its hold is clamped there).
  for (int f : {hand::kIndex, hand::kRing}) {
    const hand::DigitParams d = hand::digit_params(f);
    Mat3 ref = Mat3::Zero();
    for (int p : {d.flexion, d.abduction, d.distal}) ref += tip_motion(m, q, f, p) * tip_motion(m, q, f, p).transpose();
    ref /= Eigen::SelfAdjointEigenSolver<Mat3>(ref).eigenvalues().maxCoeff();
    const auto& h = holds[static_cast<std::size_t>(f)];
    ASSERT_LT(h.scale.maxCoeff(), device::kMaxHoldScale) << "finger " << f << ": none clamped";
    EXPECT_LT((compliance(h) - ref).norm(), 1e-4) << "finger " << f << "\n" << compliance(h) << "\n" << ref;
    EXPECT_NEAR(h.scale.minCoeff(), 1.0, 1e-9);
    EXPECT_LT((h.R_WE.transpose() * h.R_WE - Mat3::Identity()).norm(), 1e-9);
  }
}

TEST(FingerHold, TheMiddleFingerCannotYieldSideways) {
  const hand::HandModel m = user_right();
  const hand::HandParams q = mid_range(m);
  const auto holds = finger_holds(m, q);
  const auto& h = holds[hand::kMiddle];
  // Its two joints move the fingertip in a plane; across it (their cross product) the hold is
  // as stiff as it gets, in the plane it yields.
  const Vec3 a = tip_motion(m, q, hand::kMiddle, hand::kMiddleMcpFlexion);
  const Vec3 b = tip_motion(m, q, hand::kMiddle, hand::kMiddleDip);
  const Vec3 across = a.cross(b).normalized();
  int stiff = 0;
  for (int i = 0; i < 3; ++i) {
    if (h.scale[i] < device::kMaxHoldScale) continue;
    ++stiff;
    EXPECT_GT(std::abs(h.R_WE.col(i).dot(across)), 0.999);
  }
  EXPECT_EQ(stiff, 1);
  EXPECT_GT(a.normalized().dot(compliance(h) * a.normalized()), 0.1);
  EXPECT_LT(across.dot(compliance(h) * across), 1.0 / device::kMaxHoldScale + 1e-9);
}

TEST(FingerHold, AJointAtItsLimitStiffensTheFingertipAlongItsMotion) {
  const hand::HandModel m = user_right();
  hand::HandParams q = mid_range(m);
  const Vec3 abduct = tip_motion(m, q, hand::kIndex, hand::kIndexMcpAbduction).normalized();
  const double free = abduct.dot(compliance(finger_holds(m, q)[hand::kIndex]) * abduct);
  q[hand::kIndexMcpAbduction] = m.limits.lower[hand::kIndexMcpAbduction];
  const Vec3 at_limit = tip_motion(m, q, hand::kIndex, hand::kIndexMcpAbduction).normalized();
  const double held = at_limit.dot(compliance(finger_holds(m, q)[hand::kIndex]) * at_limit);
  EXPECT_LT(held, 0.1 * free) << free << " → " << held;
  // The other fingers do not care.
  EXPECT_LT((compliance(finger_holds(m, q)[hand::kRing]) - compliance(finger_holds(m, mid_range(m))[hand::kRing])).norm(), 1e-9);
}

TEST(FingerHold, TurnsWithTheHand) {
  const hand::HandModel m = user_right();
  hand::HandParams q = mid_range(m);
  const auto before = finger_holds(m, q);
  const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(0.2, -1, 0.4).normalized()).toRotationMatrix();
  const Eigen::AngleAxisd turned(R * hand::hand_pose(q).R);
  q.set_wrist(R * q.p_W_wrist(), turned.angle() * turned.axis());
  const auto after = finger_holds(m, q);
  for (int f = 0; f < hand::kFingertipCount; ++f)
    EXPECT_LT((compliance(after[f]) - R * compliance(before[f]) * R.transpose()).norm(), 1e-5) << "finger " << f;
}

}  // namespace
}  // namespace spidar::sim
