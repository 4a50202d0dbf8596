// Coupling of the last two joints, joint limits and parameter bookkeeping.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "spidar/hand/coupling.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {
namespace {

using units::deg_to_rad;

TEST(Coupling, PaperQuadraticValues) {
  // θ2 = 1.1341·θ1² − 0.286·θ1: dips to ≈ −0.018 at θ1 ≈ 0.126 (the paper's coupling).
  const auto dip = couple(Coupling::kPaperQuadratic, 0.126);
  EXPECT_NEAR(dip.penultimate, -0.018, 5e-4);
  EXPECT_NEAR(dip.penultimate, 1.1341 * 0.126 * 0.126 - 0.286 * 0.126, 1e-15);
  // The minimum is at θ1 = 0.286 / (2·1.1341), where the derivative vanishes.
  const double t_min = 0.286 / (2.0 * 1.1341);
  EXPECT_NEAR(couple(Coupling::kPaperQuadratic, t_min).d_penultimate, 0.0, 1e-15);
  EXPECT_NEAR(couple(Coupling::kPaperQuadratic, t_min).penultimate, -0.01803, 1e-5);
  EXPECT_EQ(couple(Coupling::kPaperQuadratic, 0.0).penultimate, 0.0);
  EXPECT_NEAR(couple(Coupling::kPaperQuadratic, 1.4).penultimate, 1.1341 * 1.96 - 0.286 * 1.4,
              1e-12);
  // Monotonic increasing after the dip.
  double prev = couple(Coupling::kPaperQuadratic, t_min).penultimate;
  for (double t = t_min + 0.01; t <= 1.4; t += 0.01) {
    const double v = couple(Coupling::kPaperQuadratic, t).penultimate;
    EXPECT_GT(v, prev);
    prev = v;
  }
}

TEST(Coupling, LinearIsTwoThirds) {
  for (double pip : {0.0, 0.3, 1.2, 1.9}) {
    const double dip = 2.0 / 3.0 * pip;
    const auto c = couple(Coupling::kLinear, dip);
    EXPECT_NEAR(c.penultimate, pip, 1e-15);
    EXPECT_DOUBLE_EQ(c.d_penultimate, 1.5);
  }
}

TEST(Coupling, DerivativeMatchesCentralDifferences) {
  const double h = 1e-6;
  for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
    for (double t = 0.0; t <= 1.5; t += 0.05) {
      const double fd =
          (couple(coupling, t + h).penultimate - couple(coupling, t - h).penultimate) / (2 * h);
      EXPECT_NEAR(couple(coupling, t).d_penultimate, fd, 1e-8);
    }
  }
}

TEST(Coupling, DistalForPenultimateInvertsTheIncreasingBranch) {
  for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
    for (double y = 0.0; y <= 2.0; y += 0.1) {
      const double t = distal_for_penultimate(coupling, y);
      EXPECT_GE(t, 0.0);
      EXPECT_NEAR(couple(coupling, t).penultimate, y, 1e-12);
      EXPECT_GE(couple(coupling, t).d_penultimate, 0.0);
    }
  }
}

TEST(Coupling, Names) {
  EXPECT_EQ(coupling_from_name("quadratic"), Coupling::kPaperQuadratic);
  EXPECT_EQ(coupling_from_name("linear"), Coupling::kLinear);
  EXPECT_FALSE(coupling_from_name("cubic").has_value());
  EXPECT_EQ(coupling_name(Coupling::kLinear), "linear");
}

TEST(JointLimits, DistalLimitKeepsBothCoupledJointsInRange) {
  const JointRanges r;
  for (auto coupling : {Coupling::kPaperQuadratic, Coupling::kLinear}) {
    const auto lim = parameter_limits(r, coupling);
    for (int p : {kIndexDip, kMiddleDip, kRingDip}) {
      EXPECT_EQ(lim.lower[p], 0.0);
      EXPECT_LE(lim.upper[p], r.dip_flexion.hi);
      EXPECT_LE(couple(coupling, lim.upper[p]).penultimate, r.pip_flexion.hi + 1e-12);
    }
    EXPECT_LE(couple(coupling, lim.upper[kThumbIp]).penultimate, r.thumb_mcp_flexion.hi + 1e-12);
  }
  // Quadratic: PIP reaches 110° at DIP ≈ 82.1°, before the DIP's own 90°.
  const auto quad = parameter_limits(r, Coupling::kPaperQuadratic);
  EXPECT_NEAR(couple(Coupling::kPaperQuadratic, quad.upper[kIndexDip]).penultimate,
              deg_to_rad(110.0), 1e-12);
  EXPECT_NEAR(quad.upper[kIndexDip], 1.43326, 1e-4);
  // Linear: DIP = ⅔·110° = 73.3°.
  const auto lin = parameter_limits(r, Coupling::kLinear);
  EXPECT_NEAR(lin.upper[kIndexDip], deg_to_rad(110.0) * 2.0 / 3.0, 1e-12);
  // The paper's ranges on the direct parameters; the wrist is free.
  EXPECT_NEAR(quad.lower[kIndexMcpFlexion], deg_to_rad(-15.0), 1e-15);
  EXPECT_NEAR(quad.upper[kRingMcpFlexion], deg_to_rad(90.0), 1e-15);
  EXPECT_NEAR(quad.upper[kIndexMcpAbduction], deg_to_rad(20.0), 1e-15);
  EXPECT_NEAR(quad.lower[kThumbCmcFlexion], deg_to_rad(-60.0), 1e-15);
  EXPECT_NEAR(quad.upper[kThumbCmcAbduction], deg_to_rad(70.0), 1e-15);
  for (int i = kWristX; i <= kWristRotZ; ++i) {
    EXPECT_TRUE(std::isinf(quad.lower[i]) && quad.lower[i] < 0);
    EXPECT_TRUE(std::isinf(quad.upper[i]) && quad.upper[i] > 0);
  }
}

TEST(JointLimits, ClampPutsEveryParameterInRange) {
  const auto lim = parameter_limits(JointRanges{}, Coupling::kPaperQuadratic);
  HandParams p;
  p.q.setConstant(10.0);
  p.q[kIndexMcpAbduction] = -10.0;
  p.q[kMiddleDip] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(within_limits(p, lim));
  const HandParams c = clamp_to_limits(p, lim);
  EXPECT_TRUE(within_limits(c, lim));
  EXPECT_TRUE(c.q.allFinite());
  EXPECT_EQ(c.q[kWristX], 10.0);     // unbounded
  EXPECT_EQ(c.q[kWristRotZ], 10.0);  // unbounded
  EXPECT_EQ(c.q[kIndexMcpFlexion], lim.upper[kIndexMcpFlexion]);
  EXPECT_EQ(c.q[kIndexMcpAbduction], lim.lower[kIndexMcpAbduction]);
  EXPECT_NEAR(c.q[kMiddleDip], 0.5 * (lim.lower[kMiddleDip] + lim.upper[kMiddleDip]), 1e-15);
  // In-range values are untouched.
  HandParams z;
  EXPECT_TRUE(within_limits(z, lim));
  EXPECT_EQ(clamp_to_limits(z, lim).q, z.q);
}

// The passive range widens exactly the fingers' MCP joints: hyperextension past the flexion's
// lower end, abduction past both ends; the thumb, the distal joints and the wrist keep their box.
TEST(JointLimits, PassiveRangeWidensOnlyTheFingersMcpJoints) {
  const auto active = parameter_limits(JointRanges{}, Coupling::kPaperQuadratic);
  const PassiveRange passive{.mcp_extension = 0.2, .mcp_abduction = 0.1};
  const auto wide = passive_limits(active, passive);
  for (int i = 0; i < kParamCount; ++i) {
    const bool flexion = i == kIndexMcpFlexion || i == kMiddleMcpFlexion || i == kRingMcpFlexion;
    const bool abduction = i == kIndexMcpAbduction || i == kRingMcpAbduction;
    const double lo = flexion ? 0.2 : abduction ? 0.1 : 0.0;
    const double hi = abduction ? 0.1 : 0.0;
    if (std::isinf(active.lower[i])) {
      EXPECT_EQ(wide.lower[i], active.lower[i]) << param_name(i);
      EXPECT_EQ(wide.upper[i], active.upper[i]) << param_name(i);
      continue;
    }
    EXPECT_NEAR(active.lower[i] - wide.lower[i], lo, 1e-15) << param_name(i);
    EXPECT_NEAR(wide.upper[i] - active.upper[i], hi, 1e-15) << param_name(i);
  }
  // The defaults are the clinical low ends: 15° of hyperextension, 10° of abduction.
  const auto def = passive_limits(active);
  EXPECT_NEAR(def.lower[kMiddleMcpFlexion], deg_to_rad(-30.0), 1e-12);
  EXPECT_NEAR(def.upper[kRingMcpAbduction], deg_to_rad(30.0), 1e-12);
}

TEST(JointLimits, ValidationNamesTheRange) {
  JointRanges r;
  EXPECT_TRUE(validate_joint_ranges(r).ok());
  r.pip_flexion = {deg_to_rad(100.0), deg_to_rad(20.0)};
  auto s = validate_joint_ranges(r);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("pip_flexion"), std::string::npos) << s.error().message;
  r = JointRanges{};
  r.dip_flexion.lo = deg_to_rad(-10.0);
  s = validate_joint_ranges(r);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("dip_flexion"), std::string::npos) << s.error().message;
}

TEST(Parameters, NamesAndDigits) {
  EXPECT_EQ(param_name(kIndexMcpAbduction), "index_mcp_abduction");
  EXPECT_EQ(param_name(kRingDip), "ring_dip");
  EXPECT_EQ(param_name(kLittleDip), "little_dip");
  EXPECT_EQ(param_name(kParamCount), "invalid");
  EXPECT_EQ(joint_name(joint_index(kThumb, 0)), "thumb_cmc");
  EXPECT_EQ(joint_name(joint_index(kIndex, 1)), "index_pip");
  EXPECT_EQ(joint_name(joint_index(kLittle, 3)), "little_tip");
  EXPECT_EQ(kJointCount, 21);
  EXPECT_EQ(digit_params(kMiddle).abduction, -1);
  EXPECT_EQ(digit_params(kLittle).flexion, kRingMcpFlexion);
  EXPECT_EQ(digit_params(kLittle).distal, kRingDip);
  EXPECT_EQ(digit_params(kLittle, true).flexion, kLittleMcpFlexion);
  EXPECT_EQ(digit_params(kRing, true).flexion, kRingMcpFlexion);
  // Every parameter belongs to exactly one of the wrist and the five digits with a little finger
  // of its own; the paper's 17 to the wrist and the four measured digits.
  int count[kParamCount] = {};
  for (int i = kWristX; i <= kWristRotZ; ++i) ++count[i];
  for (int f = kThumb; f <= kLittle; ++f) {
    const auto d = digit_params(f, true);
    ++count[d.flexion];
    ++count[d.distal];
    if (d.abduction >= 0) ++count[d.abduction];
  }
  for (int i = 0; i < kParamCount; ++i) EXPECT_EQ(count[i], 1) << param_name(i);
}

TEST(Parameters, MirrorIsAnInvolution) {
  HandParams p;
  for (int i = 0; i < kParamCount; ++i) p.q[i] = 0.1 * (i + 1);
  const HandParams m = mirror_params(p);
  EXPECT_EQ(m.q[kWristX], -p.q[kWristX]);
  EXPECT_EQ(m.q[kWristY], p.q[kWristY]);
  EXPECT_EQ(m.q[kWristRotX], p.q[kWristRotX]);
  EXPECT_EQ(m.q[kWristRotY], -p.q[kWristRotY]);
  EXPECT_EQ(m.q.tail<11>(), p.q.tail<11>());
  EXPECT_EQ(mirror_params(m).q, p.q);
}

}  // namespace
}  // namespace spidar::hand
