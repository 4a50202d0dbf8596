// Per-digit reach of the string-measured caps (fingertip_reach.hpp), against independent
// references: a reachable cap against the pose that produced it, an unreachable one against a
// brute-force grid over the digit's parameters, and the successive adjustment's stall at the
// straight finger against the re-fit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "registration_test_util.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/fingertip_reach.hpp"

namespace spidar::registration {
namespace {

/// A random pose of every digit within the limits (the wrist as given).
hand::HandParams random_digits(const hand::HandModel& model, const hand::HandParams& base, std::mt19937* rng) {
  hand::HandParams q = base;
  for (int k = hand::kThumbCmcFlexion; k < hand::kParamCount; ++k) {
    std::uniform_real_distribution<double> u(model.limits.lower[k], model.limits.upper[k]);
    q[k] = u(*rng);
  }
  return q;
}

TEST(FingertipReach, ReachesEveryReachableCapFromStraightFingers) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams base = test::reaching_hands(0)[1];
  std::mt19937 rng(3);
  double worst_mm = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const hand::HandParams truth = random_digits(model, base, &rng);
    const HandObservation obs = test::exact_caps(model, truth);
    // Start: every digit straight (distal at its lower limit), flexion and abduction elsewhere.
    hand::HandParams q = random_digits(model, base, &rng);
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      const int d = hand::digit_params(f).distal;
      q[d] = model.limits.lower[d];
    }
    const FingertipReach r = reach_fingertips(model, obs, {}, &q);
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      worst_mm = std::max(worst_mm, 1e3 * r.miss_after_m[f]);
    }
    // The wrist never moves, and the result is what it says.
    EXPECT_EQ(q.q.head<6>(), base.q.head<6>());
    const auto misses = fingertip_misses(model, obs, q);
    for (int f = 0; f < hand::kFingertipCount; ++f) EXPECT_NEAR(misses[f], r.miss_after_m[f], 1e-12);
    for (int k = hand::kThumbCmcFlexion; k < hand::kParamCount; ++k) {
      EXPECT_GE(q[k], model.limits.lower[k] - 1e-12) << hand::param_name(k);
      EXPECT_LE(q[k], model.limits.upper[k] + 1e-12) << hand::param_name(k);
    }
  }
  std::printf("40 random poses, every digit started straight: worst cap miss %.4f mm\n", worst_mm);
  EXPECT_LT(worst_mm, 0.05);
}

TEST(FingertipReach, AnUnreachableCapEndsAsNearAsABruteForceGridFinds) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams base = test::reaching_hands(0)[1];
  const hand::HandPoints pts = hand::forward_kinematics(model, base);
  for (int f = hand::kIndex; f <= hand::kRing; ++f) {
    HandObservation obs = test::exact_caps(model, base);
    // 2 cm beyond the finger's reach along the hand's axis, and 1 cm dorsal.
    const Pose X_WH = hand::hand_pose(base);
    obs.p_W_fingertip[f] = pts.p_W_fingertip[f] + X_WH.R * Vec3(0.0, 0.02, 0.01);
    hand::HandParams q = base;
    const FingertipReach r = reach_fingertips(model, obs, {}, &q);
    // The reference: every combination of the digit's parameters on a grid.
    const hand::DigitParams cols = hand::digit_params(f);
    const int steps = 40;
    double best = std::numeric_limits<double>::infinity();
    auto axis = [&](int k, int i) {
      return k < 0 ? 0.0 : model.limits.lower[k] + (model.limits.upper[k] - model.limits.lower[k]) * i / steps;
    };
    for (int a = 0; a <= steps; ++a)
      for (int b = 0; b <= (cols.abduction >= 0 ? steps : 0); ++b)
        for (int c = 0; c <= steps; ++c) {
          hand::HandParams g = base;
          g[cols.flexion] = axis(cols.flexion, a);
          if (cols.abduction >= 0) g[cols.abduction] = axis(cols.abduction, b);
          g[cols.distal] = axis(cols.distal, c);
          best = std::min(best, fingertip_misses(model, obs, g)[f]);
        }
    std::printf("%s: reach %.3f mm, grid %.3f mm\n", std::string(hand::param_name(cols.flexion)).c_str(),
                1e3 * r.miss_after_m[f], 1e3 * best);
    EXPECT_LE(r.miss_after_m[f], best + 1e-5) << "finger " << f;
    EXPECT_GT(r.miss_after_m[f], 0.005) << "the target is out of reach";
  }
}

TEST(FingertipReach, LeavesNearCapsUnmeasuredCapsAndBrokenPosesAlone) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams base = test::reaching_hands(0)[1];
  HandObservation obs = test::exact_caps(model, base);
  obs.p_W_fingertip[hand::kIndex] += Vec3(0.0005, 0, 0);  // 0.5 mm off: within min_miss
  obs.fingertip_valid[hand::kMiddle] = false;
  obs.p_W_fingertip[hand::kMiddle] += Vec3(0.03, 0, 0);
  obs.p_W_fingertip[hand::kRing] = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  hand::HandParams q = base;
  const FingertipReach r = reach_fingertips(model, obs, {.min_miss_m = 0.001}, &q);
  EXPECT_EQ(r.changed_count(), 0);
  EXPECT_EQ(q.q, base.q);
  hand::HandParams broken = base;
  broken[hand::kIndexDip] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(reach_fingertips(model, test::exact_caps(model, base), {}, &broken).changed_count(), 0);
  EXPECT_EQ(reach_fingertips(model, obs, {}, nullptr).changed_count(), 0);
}

TEST(FingertipReach, TheRefitLeavesTheBasinTheTemporalPriorHolds) {
  // The left index of registration_study --model-user: bent at the truth, fitted nearly straight
  // with the MCP flexed to make up for it (the best cap a straight finger reaches, found on a
  // grid). The temporal prior at that pose (σ 0.3 rad) holds the next frame's fit there, short of
  // the string; the re-fit moves the digit and its prior to the caps.
  const hand::HandModel model = hand::default_hand_model(hand::Side::kLeft);
  hand::HandParams truth = test::reaching_hands(0)[0];
  truth[hand::kIndexMcpFlexion] = 0.2;
  truth[hand::kIndexDip] = 1.2;
  truth = hand::clamp_to_limits(truth, model.limits);
  const HandObservation obs = test::exact_caps(model, truth);
  hand::HandParams held = truth;
  held[hand::kIndexDip] = model.limits.lower[hand::kIndexDip];
  double nearest = std::numeric_limits<double>::infinity();
  for (int a = 0; a <= 60; ++a)
    for (int b = 0; b <= 60; ++b) {
      hand::HandParams g = held;
      g[hand::kIndexMcpFlexion] = model.limits.lower[hand::kIndexMcpFlexion] +
                                  (model.limits.upper[hand::kIndexMcpFlexion] - model.limits.lower[hand::kIndexMcpFlexion]) * a / 60;
      g[hand::kIndexMcpAbduction] = model.limits.lower[hand::kIndexMcpAbduction] +
                                    (model.limits.upper[hand::kIndexMcpAbduction] - model.limits.lower[hand::kIndexMcpAbduction]) * b / 60;
      const double m = fingertip_misses(model, obs, g)[hand::kIndex];
      if (m < nearest) {
        nearest = m;
        held = g;
      }
    }
  const SuccessiveAdjustment solver{RegistrationParams{}};
  const ImageEvidence no_image;
  hand::HandParams q = held;
  FitReport report = solver.fit(model, obs, no_image, &held, &q);
  const auto stalled = fingertip_misses(model, obs, q);
  const int first_iterations = report.iterations;
  const double stalled_dip = q[hand::kIndexDip];
  const bool kept = refit_reaching(solver, model, obs, no_image, &held, {.min_miss_m = 0.001}, &q, &report);
  const auto reached = fingertip_misses(model, obs, q);
  std::printf("index cap: straight %.2f mm short, held by the prior %.2f mm (DIP %.2f rad for %.2f); "
              "the re-fit %.3f mm (DIP %.2f rad)\n",
              1e3 * nearest, 1e3 * stalled[hand::kIndex], stalled_dip, truth[hand::kIndexDip],
              1e3 * reached[hand::kIndex], q[hand::kIndexDip]);
  EXPECT_GT(stalled[hand::kIndex], 0.001);
  EXPECT_TRUE(kept);
  EXPECT_GT(report.iterations, first_iterations);
  // Within the fingertip σ (1.5 mm) of every string: the prior still pulls a little.
  EXPECT_LT(reached[hand::kIndex], 0.5 * stalled[hand::kIndex]);
  for (int f = 0; f < hand::kFingertipCount; ++f) EXPECT_LT(reached[f], 0.001) << "digit " << f;
  // A fit that reaches every cap is left as it is.
  const hand::HandParams before = q;
  EXPECT_FALSE(refit_reaching(solver, model, obs, no_image, &held, {.min_miss_m = 0.001}, &q, &report));
  EXPECT_EQ(q.q, before.q);
}

}  // namespace
}  // namespace spidar::registration
