// Online hand-shape personalisation (shape_estimator.hpp) against hands of known sizes: the
// strings' fingertips and the bracelet's wrist pixel are generated from a hand with other sizes
// than the model's (its own skeleton, at poses that vary as a session's do); the pose is fitted by
// the registration with the current estimate, frame after frame, as the pipeline does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "registration_test_util.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

struct Outcome {
  ShapeEstimate estimate;
  double tip_error_first_mm = 0, tip_error_last_mm = 0;  ///< fitted caps vs the true caps
};

/// Runs `frames` frames of one right hand of sizes (L, W) moving through varied poses.
Outcome run(double length_m, double width_m, int frames, std::uint32_t seed) {
  const hand::HandModel truth =
      resized(hand::default_hand_model(hand::Side::kRight), length_m, width_m).value();
  const hand::HandModel start = hand::default_hand_model(hand::Side::kRight);
  const vision::Camera camera = vision::default_rig_camera();
  RegistrationParams rp;
  ShapeEstimator est(start, {});
  SuccessiveAdjustment solver(rp);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.0003);  // strings: 0.3 mm
  const hand::HandParams base = test::reaching_hands(0)[1];
  hand::HandParams fit = base, truth_q = base;
  Outcome out;
  for (int k = 0; k < frames; ++k) {
    // A slowly varying pose: the fingers open and close, the hand turns a little.
    const double a = 0.05 * k;
    truth_q = base;
    for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i)
      truth_q[i] = base[i] + 0.35 * std::sin(a + 0.7 * i);
    truth_q.set_wrist(base.p_W_wrist() + Vec3(0.02 * std::sin(0.3 * a), 0.02 * std::cos(0.4 * a), 0.0),
                      base.r_W_hand() + Vec3(0.2 * std::sin(0.5 * a), 0.15 * std::cos(0.6 * a), 0.0));
    truth_q = hand::clamp_to_limits(truth_q, truth.limits);
    const hand::HandPoints pts = hand::forward_kinematics(truth, truth_q);
    HandObservation obs;
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      obs.p_W_fingertip[f] = pts.p_W_fingertip[f] + Vec3(noise(rng), noise(rng), noise(rng));
      obs.fingertip_valid[f] = true;
    }
    obs.wrist_px = camera.project(bracelet_visible_point(hand::hand_pose(truth_q), width_m,
                                                         camera.X_WC().p, rp));
    ImageEvidence image;
    image.camera = &camera;
    const hand::HandParams prior = fit;
    FitReport report = solver.fit(est.model(), obs, image, &prior, &fit);
    refit_reaching(solver, est.model(), obs, image, &prior, {.min_miss_m = 0.001}, &fit, &report);
    double tip = 0;
    const hand::HandPoints fp = hand::forward_kinematics(est.model(), fit);
    for (int f = 0; f < hand::kFingertipCount; ++f) tip += (fp.p_W_fingertip[f] - pts.p_W_fingertip[f]).norm() / 4;
    if (k == 0) out.tip_error_first_mm = 1e3 * tip;
    out.tip_error_last_mm = 1e3 * tip;
    est.add_frame(fit, obs, image, rp);
  }
  out.estimate = est.estimate();
  return out;
}

class KnownSizes : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(KnownSizes, LengthMovesTowardTheTruthAsEvidenceAccumulates) {
  const auto [L, W] = GetParam();
  const Outcome o = run(L, W, 400, 7);
  const ShapeEstimate& e = o.estimate;
  std::printf("truth L %.4f W %.4f: estimate L %.4f (σ %.2f mm) W %.4f (σ %.2f mm), %d keyframes; "
              "fingertips %.2f -> %.2f mm\n",
              L, W, e.length_m, 1e3 * e.sigma_length_m, e.width_m, 1e3 * e.sigma_width_m,
              e.keyframes, o.tip_error_first_mm, o.tip_error_last_mm);
  // Measured 2026-11-25 (400 frames, 24 keyframes; each frame's fit and the keyframe refits
  // re-posing digits stalled short of their strings, fingertip_reach.hpp): L 0.2105 for 0.209,
  // 0.1829 for 0.171, 0.1971 for 0.1976, 0.1799 for 0.171 (without the re-posing 0.2104, 0.1858,
  // 0.1996, 0.1792); widths 1.5–9 mm off. The length always moves toward the
  // truth, but a small hand's stops short (issue 14 keeps the 2 % target open): what is asserted
  // is the direction and the narrowing of the evidence, not the target.
  EXPECT_LT(std::abs(e.length_m - L), std::abs(0.19 - L));
  EXPECT_LT(e.sigma_length_m, 0.25 * ShapeEstimatorParams{}.prior_sigma_length_m);
  EXPECT_GE(e.keyframes, ShapeEstimatorParams{}.min_keyframes);
  EXPECT_GE(e.solves, 1);
  EXPECT_TRUE(std::isfinite(e.width_m));
}

INSTANTIATE_TEST_SUITE_P(Users, KnownSizes,
                         ::testing::Values(std::make_pair(0.209, 0.0935), std::make_pair(0.171, 0.0765),
                                           std::make_pair(0.1976, 0.0825), std::make_pair(0.171, 0.0935)));

TEST(ShapeEstimator, StaysWithinItsBoundAndFreezesNothingWithoutEvidence) {
  const hand::HandModel start = hand::default_hand_model(hand::Side::kRight);
  ShapeEstimator est(start, {});
  HandObservation none;  // no fingertips: nothing to learn
  ImageEvidence image;
  hand::HandParams q = test::reaching_hands(0)[1];
  EXPECT_FALSE(est.add_frame(q, none, image, RegistrationParams{}));
  EXPECT_EQ(est.estimate().keyframes, 0);
  EXPECT_DOUBLE_EQ(est.estimate().length_m, 0.19);
  // A far too long hand: the estimate stops at +15 %.
  const Outcome o = run(0.26, 0.085, 300, 3);
  EXPECT_LE(o.estimate.length_m, 1.15 * 0.19 + 1e-12);
  EXPECT_GT(o.estimate.length_m, 1.10 * 0.19);
}

TEST(ShapeEstimator, ParsesItsSettingsAndNamesBadOnes) {
  const auto root = core::ConfigNode::LoadFile(SPIDAR_SOURCE_DIR "/configs/registration.yaml");
  bool enabled = false;
  const ShapeEstimatorParams p = parse_shape_estimator_params(root["personalisation"], &enabled);
  EXPECT_TRUE(enabled);  // on in the shipped settings (demo, run and replay)
  // The shipped settings are the library's defaults.
  const ShapeEstimatorParams d;
  EXPECT_EQ(p.keyframes, d.keyframes);
  EXPECT_EQ(p.min_pose_change, d.min_pose_change);
  EXPECT_EQ(p.solve_every, d.solve_every);
  EXPECT_EQ(p.min_keyframes, d.min_keyframes);
  EXPECT_EQ(p.prior_sigma_length_m, d.prior_sigma_length_m);
  EXPECT_EQ(p.prior_sigma_width_m, d.prior_sigma_width_m);
  EXPECT_EQ(p.max_relative_change, d.max_relative_change);
  EXPECT_EQ(p.reach_min_miss_m, d.reach_min_miss_m);
  EXPECT_EQ(p.apply_after_frames, 5);  // the sessions re-estimate on a thread of their own
  const auto bad = core::ConfigNode::Parse("personalisation:\n  min_pose_change: -1\n", "bad.yaml");
  try {
    parse_shape_estimator_params(bad["personalisation"], &enabled);
    FAIL() << "accepted a negative pose change";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("min_pose_change"), std::string::npos) << e.what();
  }
  for (const std::string key : {"apply_after_frames", "reach_min_miss_m"}) {
    const std::string text = "personalisation:\n  " + key + (key == "apply_after_frames" ? ": -1\n" : ": 0.5\n");
    const auto node = core::ConfigNode::Parse(text, "bad.yaml");
    try {
      parse_shape_estimator_params(node["personalisation"], &enabled);
      FAIL() << "accepted " << text;
    } catch (const core::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.yaml:2"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << key << ": " << e.what();
    }
  }
  const auto on = core::ConfigNode::Parse("personalisation:\n  silhouette: true\n  reach_min_miss_m: 0\n", "on.yaml");
  const ShapeEstimatorParams q = parse_shape_estimator_params(on["personalisation"], &enabled);
  EXPECT_TRUE(q.silhouette);
  EXPECT_EQ(q.reach_min_miss_m, 0.0);
}

}  // namespace
}  // namespace spidar::registration
