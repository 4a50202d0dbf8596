// The human fingertip of the simulated device: isotropic as before, shaped by a hold (stiff
// where the finger cannot yield), bounded past the hold's range, and used by the simulated SPIDAR
// when its fingertip source gives holds.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>

#include "device_test_support.hpp"
#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/strings/motor.hpp"

namespace spidar::device {
namespace {

/// A rotation with no axis along x, y or z (so that a test cannot pass by working per axis).
Mat3 tilted() {
  return (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()) *
          Eigen::AngleAxisd(-0.4, Vec3(0, 1, -1).normalized()))
      .toRotationMatrix();
}

/// Steps a fingertip under a constant force until it settles; returns where [m].
Vec3 settle(const FingertipImpedance& imp, const FingertipHold& hold, const Vec3& goal, const Vec3& f) {
  Vec3 p = goal, v = Vec3::Zero();
  for (int i = 0; i < 40000; ++i) step_fingertip(imp, hold, goal, f, 0.25e-3, p, v);  // 10 s
  EXPECT_LT(v.norm(), 1e-9);
  return p;
}

TEST(FingertipImpedance, TheIsotropicHoldIsTheMassSpringDamper) {
  const FingertipImpedance imp;
  const Vec3 goal(0.01, -0.02, 0.03), f(0.4, -1.0, 0.2);
  Vec3 p(0.0, 0.0, 0.0), v(0.1, 0.0, -0.2);
  Vec3 p_ref = p, v_ref = v;
  for (int i = 0; i < 100; ++i) {
    step_fingertip(imp, FingertipHold{}, goal, f, 1e-4, p, v);
    // Written out: m·a = k·(goal − p) − c·v + f, semi-implicit Euler.
    const Vec3 a = (imp.stiffness * (goal - p_ref) - imp.damping * v_ref + f) / imp.mass;
    v_ref += a * 1e-4;
    p_ref += v_ref * 1e-4;
  }
  EXPECT_LT((p - p_ref).norm(), 1e-12);
  EXPECT_LT((v - v_ref).norm(), 1e-12);
}

TEST(FingertipImpedance, AShapedHoldYieldsAsItsStiffnessMatrixSays) {
  const FingertipImpedance imp;
  FingertipHold hold;
  hold.R_WE = tilted();
  hold.scale = Vec3(40.0, 6.0, 1.0);
  const Vec3 goal(0.0, 0.01, -0.02), f(0.9, -0.6, 0.5);  // small: within the hold's range
  // The reference: K = k·R·diag(scale)·Rᵀ, and at rest K·(p − goal) = f.
  const Mat3 K = imp.stiffness * hold.R_WE * hold.scale.asDiagonal() * hold.R_WE.transpose();
  const Vec3 expected = goal + K.ldlt().solve(f);
  const Vec3 p = settle(imp, hold, goal, f);
  EXPECT_LT((p - expected).norm(), 1e-9) << p.transpose() << " vs " << expected.transpose();
  // Along its softest axis it yields as the isotropic fingertip, along its stiffest 40 × less.
  const Vec3 soft = hold.R_WE.col(2), stiff = hold.R_WE.col(0);
  EXPECT_NEAR((settle(imp, hold, goal, soft) - goal).dot(soft), 1.0 / imp.stiffness, 1e-9);
  EXPECT_NEAR((settle(imp, hold, goal, stiff) - goal).dot(stiff), 1.0 / (40 * imp.stiffness), 1e-9);
}

TEST(FingertipImpedance, PastTheHoldRangeOnlyTheIsotropicSpringGrows) {
  const FingertipImpedance imp;
  FingertipHold hold;
  hold.scale = Vec3(64.0, 1.0, 1.0);
  // 40 N along the stiff axis: the hold gives k·63·range at most, the rest is k·e.
  const double F = 40.0;
  const Vec3 p = settle(imp, hold, Vec3::Zero(), Vec3(F, 0, 0));
  const double e = p.x();
  EXPECT_GT(e, imp.hold_range);
  EXPECT_NEAR(imp.stiffness * (e + 63.0 * imp.hold_range), F, 1e-6);
  // A fingertip let go from there returns without a snap: slower than 2 m/s.
  Vec3 x = p, v = Vec3::Zero();
  double v_max = 0;
  for (int i = 0; i < 4000; ++i) {
    step_fingertip(imp, hold, Vec3::Zero(), Vec3::Zero(), 0.25e-3, x, v);
    v_max = std::max(v_max, v.norm());
  }
  EXPECT_LT(v_max, 2.0);
  EXPECT_LT(x.norm(), 1e-4);
}

TEST(FingertipImpedance, TheStiffestHoldStaysStableAtTheDevicesSubSteps) {
  const FingertipImpedance imp;
  FingertipHold hold;
  hold.R_WE = tilted();
  hold.scale = Vec3::Constant(kMaxHoldScale);
  Vec3 p(0.001, -0.001, 0.0005), v(0.5, 0.2, -0.3);
  for (int i = 0; i < 4000; ++i) step_fingertip(imp, hold, Vec3::Zero(), Vec3::Zero(), 0.25e-3, p, v);
  EXPECT_LT(p.norm(), 1e-9);
  EXPECT_LT(v.norm(), 1e-9);
}

TEST(FingertipImpedance, SanitizedHoldsAreClampedAndNonFiniteOnesIsotropic) {
  FingertipHold h;
  h.scale = Vec3(0.2, 10.0, 1e6);
  const FingertipHold s = sanitized(h);
  EXPECT_EQ(s.scale, Vec3(1.0, 10.0, kMaxHoldScale));
  h.R_WE(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(sanitized(h).scale, Vec3::Ones());
  EXPECT_TRUE(sanitized(h).R_WE.isIdentity());
}

/// Still goals, every finger held with the same shaped hold.
class HeldStill final : public FingertipSource {
 public:
  HeldStill(Vec3 goal, FingertipHold hold) : goal_(goal), hold_(hold) {}
  void goals(double, std::span<Vec3> g) override {
    for (auto& p : g) p = goal_;
  }
  bool holds(std::span<FingertipHold> h) override {
    for (auto& x : h) x = hold_;
    return true;
  }

 private:
  Vec3 goal_;
  FingertipHold hold_;
};

TEST(SimulatedSpidar, AFingertipSourcesHoldShapesHowTheDisplayedForceMovesTheFingertip) {
  const auto& cfg = testing::spidar8();
  SimulatedSpidarParams params;
  params.fixed_step_s = 1e-3;
  params.count_noise = 0;
  FingertipHold hold;
  hold.R_WE = tilted();
  hold.scale = Vec3(30.0, 10.0, 1.0);
  const Vec3 goal(-0.03, 0.02, -0.01);
  SimulatedSpidar sim(cfg, params, std::make_shared<HeldStill>(goal, hold));
  ASSERT_TRUE(sim.open().ok());
  sim.clear_safe_state();
  // Pull finger 1 with 1 N on each of its strings (a net force below 3 N).
  std::vector<std::int32_t> cmd(24, sim.info().command_min);
  for (int i = 0; i < 3; ++i) cmd[3 + i] = strings::tension_to_command(cfg.motor, 1.0).dac;
  ASSERT_TRUE(sim.write(cmd).ok());
  sim.advance(2.0);
  const auto truth = sim.truth();
  const Vec3 F = truth.f_W_strings[1];
  const Mat3 K = params.impedance.stiffness * hold.R_WE * hold.scale.asDiagonal() * hold.R_WE.transpose();
  const Vec3 d = truth.p_W_fingertip[1] - goal;
  // Within the hold's range on its stiffer axes (the softest is isotropic anyway).
  const Vec3 d_E = hold.R_WE.transpose() * d;
  ASSERT_LT(std::max(std::abs(d_E.x()), std::abs(d_E.y())), params.impedance.hold_range);
  EXPECT_LT((K * d - F).norm(), 1e-4 * F.norm()) << (K * d).transpose() << " vs " << F.transpose();
}

}  // namespace
}  // namespace spidar::device
