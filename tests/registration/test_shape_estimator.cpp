// Online hand-shape personalisation (shape_estimator.hpp) against hands of known sizes: the
// strings' fingertips and the bracelet's wrist pixel are generated from a hand with other sizes
// than the model's (its own skeleton, at poses that vary as a session's do); the pose is fitted by
// the registration with the current estimate, frame after frame, as the pipeline does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "registration_test_util.hpp"
#include "spidar/core/units.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

struct Outcome {
  ShapeEstimate estimate;
  double tip_error_first_mm = 0, tip_error_last_mm = 0;  ///< fitted caps vs the true caps
  /// Over every re-estimate: the largest rise of its objective from its start to its result
  /// (ShapeEstimate::objective − objective_start; ≤ 0 when each keeps the lowest it visited).
  double objective_rise_max = -std::numeric_limits<double>::infinity();
};

/// Feeds `frames` frames of hand `hand` of `est` (its side's model as est.model(hand)): a hand of
/// `truth`'s sizes moving through varied poses about `base`, the strings' fingertips (0.3 mm noise)
/// and the bracelet's wrist pixel generated from its own skeleton, the pose fitted by the
/// registration with the current estimate, frame after frame, as the pipeline does. With
/// `silhouette` other than kNone the camera also sees the hand's silhouette, drawn from its own
/// capsules and palm box (test::draw_capsule_mask): the model's geometry, so this checks the
/// estimator's use of the image, not the model's fidelity.
Outcome feed(ShapeEstimator& est, int hand, const hand::HandModel& truth, const hand::HandParams& base,
             int frames, std::uint32_t seed, ShapeSilhouette silhouette = ShapeSilhouette::kNone,
             bool matte = false, bool box_palm = true, bool exact_digits = false) {
  const vision::Camera camera = vision::default_rig_camera();
  RegistrationParams rp;
  SuccessiveAdjustment solver(rp);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.0003);  // strings: 0.3 mm
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
    obs.wrist_px = camera.project(bracelet_visible_point(hand::hand_pose(truth_q), truth.shape.dimensions.width,
                                                         camera.X_WC().p, rp));
    ImageEvidence image;
    image.camera = &camera;
    cv::Mat mask;
    if (silhouette != ShapeSilhouette::kNone || matte) {
      test::draw_capsule_mask(truth, truth_q, camera, &mask, box_palm, exact_digits);
      mask.convertTo(image.alpha, CV_32FC1, 1.0 / 255.0);
    }
    const hand::HandModel& model = est.model(hand);
    const hand::HandParams prior = fit;
    FitReport report = solver.fit(model, obs, image, &prior, &fit);
    refit_reaching(solver, model, obs, image, &prior, {.min_miss_m = 0.001}, &fit, &report);
    double tip = 0;
    const hand::HandPoints fp = hand::forward_kinematics(est.model(hand), fit);
    for (int f = 0; f < hand::kFingertipCount; ++f) tip += (fp.p_W_fingertip[f] - pts.p_W_fingertip[f]).norm() / 4;
    if (k == 0) out.tip_error_first_mm = 1e3 * tip;
    out.tip_error_last_mm = 1e3 * tip;
    // The pose fit used no matte (no joint-balls); the estimator takes the silhouette from it.
    const int solves = est.estimate(hand).solves;
    est.add_frame(hand, fit, obs, image, rp);
    const ShapeEstimate& e = est.estimate(hand);
    if (e.solves > solves) out.objective_rise_max = std::max(out.objective_rise_max, e.objective - e.objective_start);
  }
  out.estimate = est.estimate(hand);
  return out;
}

/// One right hand of sizes (L, W) and digit thickness `thickness`, estimated from the default
/// model (feed()).
Outcome run(double length_m, double width_m, int frames, std::uint32_t seed,
            ShapeSilhouette silhouette = ShapeSilhouette::kNone, double thickness = 1.0,
            bool joint_balls = false) {
  const hand::HandModel truth =
      resized(hand::default_hand_model(hand::Side::kRight), length_m, width_m, thickness).value();
  ShapeEstimatorParams sp;
  sp.silhouette = silhouette;
  sp.joint_balls = joint_balls;
  sp.digit_section_sigma = 0.0;  // each test here weighs one kind of evidence (the sections: below)
  ShapeEstimator est(hand::default_hand_model(hand::Side::kRight), sp);
  return feed(est, 0, truth, test::reaching_hands(0)[1], frames, seed, silhouette, joint_balls);
}

/// Started at the true sizes of a default-sized hand with linear coupling, on exact skeleton data
/// (feed(), 400 frames): the estimate's relative length error at the end, printed under `label`.
double drift_from_the_truth(const ShapeEstimatorParams& sp, const char* label) {
  const hand::HandModel truth =
      resized(hand::default_hand_model(hand::Side::kRight, hand::Coupling::kLinear), 0.1976, 0.0825).value();
  ShapeEstimator est(truth, sp);
  const Outcome o = feed(est, 0, truth, test::reaching_hands(0)[1], 400, 7);
  std::printf("%s: L %.4f W %.4f from the truth 0.1976, 0.0825 (%d solves)\n", label, o.estimate.length_m,
              o.estimate.width_m, o.estimate.solves);
  EXPECT_GE(o.estimate.solves, 1) << label;
  return o.estimate.length_m / 0.1976 - 1;
}

/// Parsing `text` (file `file`) fails with a message naming file:2 and `want`.
void expect_parse_error(const std::string& text, const std::string& file, const std::string& want) {
  const auto node = core::ConfigNode::Parse(text, file);
  bool enabled = false;
  try {
    parse_shape_estimator_params(node["personalisation"], &enabled);
    ADD_FAILURE() << "accepted " << text;
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(file + ":2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << want << ": " << e.what();
  }
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

// A model longer and thicker than the hand bends its fingers to reach the caps, so the strings
// hardly shorten it; the silhouette's spill (model points outside the outline) does, and sees the
// digits' thickness, which the strings cannot.
TEST(ShapeEstimator, TheSilhouettesSpillShortensAndThinsAnOversizedModel) {
  const double L = 0.175, W = 0.08, T = 0.85;
  const Outcome strings = run(L, W, 240, 11);
  const Outcome spill = run(L, W, 240, 11, ShapeSilhouette::kSpill, T);
  const ShapeEstimate& a = strings.estimate;
  const ShapeEstimate& b = spill.estimate;
  std::printf("truth L %.4f W %.4f T %.2f: strings L %.4f W %.4f T %.2f; with the spill L %.4f W %.4f "
              "T %.3f (σ %.3f), %d solves\n",
              L, W, T, a.length_m, a.width_m, a.thickness, b.length_m, b.width_m, b.thickness,
              b.sigma_thickness, b.solves);
  EXPECT_EQ(a.thickness, 1.0);  // nothing sees it
  EXPECT_LT(b.thickness, 0.95);
  // One-sided evidence: the spill's rows vanish as the model comes inside the outline, so the
  // thickness stays uncertain (measured 2026-11-25: T 0.933 for 0.85, σ 0.073; L 0.1748 against
  // the strings' 0.1870; W 0.0812 against 0.0844).
  EXPECT_LT(b.sigma_thickness, ShapeEstimatorParams{}.prior_sigma_thickness);
  EXPECT_LT(std::abs(b.length_m - L), std::abs(a.length_m - L));
  EXPECT_LT(std::abs(b.length_m - L), std::abs(0.19 - L));
}

// The same with the joint-balls (the paper's image term) in the re-estimates: a model too long
// for the hand bends its fingers to reach the caps, and their joints leave the real fingers'
// silhouettes, which the balls see.
TEST(ShapeEstimator, TheJointBallsShortenALongModel) {
  for (const auto& [L, W] : {std::pair{0.171, 0.0765}, std::pair{0.175, 0.0935}}) {
    const Outcome strings = run(L, W, 240, 11);
    const Outcome balls = run(L, W, 240, 11, ShapeSilhouette::kNone, 1.0, true);
    const ShapeEstimate& a = strings.estimate;
    const ShapeEstimate& b = balls.estimate;
    std::printf("truth L %.4f W %.4f: strings L %.4f W %.4f; with the joint-balls L %.4f W %.4f (σ L %.2f mm), "
                "%d solves\n",
                L, W, a.length_m, a.width_m, b.length_m, b.width_m, 1e3 * b.sigma_length_m, b.solves);
    EXPECT_EQ(b.thickness, 1.0);  // the balls do not estimate it
    EXPECT_LT(std::abs(b.length_m - L), std::abs(a.length_m - L)) << L << ", " << W;
    EXPECT_LT(std::abs(b.length_m - L), 0.5 * std::abs(0.19 - L)) << L << ", " << W;
  }
}

// The strings leave the width weakly seen: a narrower model reaches the same fingertips by
// spreading its fingers. The palm's breadth in the image (palm_breadth.hpp) sees it. The hand
// here faces the camera, its silhouette drawn with the palm the chords assume (a box's corners
// would add 3 % face on and 10 % turned by 0.4 rad: the model's fidelity, not the estimator's).
TEST(ShapeEstimator, ThePalmsBreadthWidensANarrowModel) {
  const double L = 0.19, W = 0.0935;
  const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), L, W).value();
  hand::HandParams base = test::reaching_hands(0)[1];
  const Mat3 R = Eigen::AngleAxisd(units::deg_to_rad(40.0), Vec3::UnitX()) * hand::rotation_from_vector(base.r_W_hand());
  const Eigen::AngleAxisd aa(R);
  base.set_wrist(base.p_W_wrist(), aa.angle() * aa.axis());
  auto estimate = [&](double sigma_px) {
    ShapeEstimatorParams sp;
    sp.joint_balls = false;
    sp.digit_section_sigma = 0.0;  // the palm's chords alone
    sp.palm_breadth_sigma_px = sigma_px;
    ShapeEstimator est(hand::default_hand_model(hand::Side::kRight), sp);
    return feed(est, 0, truth, base, 240, 13, ShapeSilhouette::kNone, true, false).estimate;
  };
  const ShapeEstimate strings = estimate(0.0), chords = estimate(2.0);
  std::printf("truth W %.4f: strings W %.4f (σ %.2f mm), with the palm's chords W %.4f (σ %.2f mm, %d chords of %d "
              "keyframes)\n",
              W, strings.width_m, 1e3 * strings.sigma_width_m, chords.width_m, 1e3 * chords.sigma_width_m,
              chords.palm_chords, chords.keyframes);
  EXPECT_EQ(strings.palm_chords, 0);
  // Most keyframes' thumbs lie on the palm's line beyond its edge (measured 4 chords of 24 kept).
  EXPECT_GT(chords.palm_chords, 0);
  EXPECT_LT(chords.sigma_width_m, 0.5 * strings.sigma_width_m);
  EXPECT_LT(std::abs(chords.width_m - W), 0.5 * std::abs(strings.width_m - W));
  EXPECT_LT(std::abs(chords.width_m - W), 0.04 * W);
}

// ShapeEstimatorParams::accumulate: a keyframe that leaves the window hands its information on
// to the prior, so the estimate weighs every pose of the session. With a window of 8 keyframes
// over 300 frames, the window alone ends about as uncertain as 8 poses leave it; accumulated, its
// σ is the session's, and the sizes stay near the truth (exact skeleton data, feed()).
TEST(ShapeEstimator, AccumulatedEvidenceOutlivesTheWindow) {
  const double L = 0.2, W = 0.09;
  const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), L, W).value();
  auto estimate = [&](bool accumulate) {
    ShapeEstimatorParams sp;
    sp.keyframes = 8;
    sp.min_keyframes = 6;
    sp.solve_every = 4;
    sp.digit_section_sigma = 0.0;
    sp.joint_balls = false;
    sp.accumulate = accumulate;
    ShapeEstimator est(hand::default_hand_model(hand::Side::kRight), sp);
    return feed(est, 0, truth, test::reaching_hands(0)[1], 300, 7).estimate;
  };
  const ShapeEstimate window = estimate(false), all = estimate(true);
  std::printf("truth L %.4f W %.4f: window L %.4f (σ %.2f mm) W %.4f (σ %.2f mm); accumulated L %.4f (σ %.2f mm) "
              "W %.4f (σ %.2f mm); %d / %d solves\n",
              L, W, window.length_m, 1e3 * window.sigma_length_m, window.width_m, 1e3 * window.sigma_width_m,
              all.length_m, 1e3 * all.sigma_length_m, all.width_m, 1e3 * all.sigma_width_m, window.solves, all.solves);
  EXPECT_GE(all.solves, 10);
  EXPECT_LT(all.sigma_length_m, 0.5 * window.sigma_length_m);
  EXPECT_LT(all.sigma_width_m, 0.5 * window.sigma_width_m);
  EXPECT_LT(std::abs(all.length_m - L), 0.02 * L);
  EXPECT_LT(std::abs(all.width_m - W), 0.05 * W);
}

/// The reaching right hand with its fingers nearly straight, so that most frames show their middle
/// phalanges across (the reaching pose's are mostly seen end-on).
hand::HandParams nearly_straight_hand() {
  hand::HandParams base = test::reaching_hands(0)[1];
  for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) base[i] *= 0.2;
  return base;
}

/// The estimate from the default right model, the strings and the digits' sections of `truth`
/// about `base` (feed(), exact digits, 240 frames; no joint-balls): `sp` as given otherwise.
ShapeEstimate estimate_with_sections(const hand::HandModel& truth, const hand::HandParams& base,
                                     ShapeEstimatorParams sp) {
  sp.joint_balls = false;
  ShapeEstimator est(hand::default_hand_model(hand::Side::kRight), sp);
  return feed(est, 0, truth, base, 240, 13, ShapeSilhouette::kNone, true, true, true).estimate;
}

// The digits' sections (digit_section_sigma): the fingers' middle phalanges seen across, whose
// width against the model's outline measures the capsules' radius (width × thickness; both are
// estimated then). Hands of the model's length and width with thicker and thinner digits (±20 %),
// their silhouettes drawn from their own capsules: the strings leave the thickness at the
// model's, the sections bring it most of the way. (They read a bent finger's digits a few per cent
// thick: a section a third of the way along a phalanx may cross the next bone's rounded end, and
// one across a fitted bone turned from the real one is oblique; docs/measurements.md.)
TEST(ShapeEstimator, TheDigitsSectionsSeeTheDigitsThickness) {
  for (const double T : {1.2, 0.8}) {
    hand::HandDimensions d = hand::default_hand_model(hand::Side::kRight).shape.dimensions;
    const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), d.length, d.width, T).value();
    const hand::HandParams base = nearly_straight_hand();
    auto estimate = [&](double sigma) {
      ShapeEstimatorParams sp;
      sp.digit_section_sigma = sigma;
      return estimate_with_sections(truth, base, sp);
    };
    const ShapeEstimate strings = estimate(0.0), sections = estimate(0.3);
    const double r_true = d.width * T, r_sections = sections.width_m * sections.thickness;
    std::printf("truth W %.4f × %.2f: strings W %.4f × %.3f, with the digits' sections W %.4f × %.3f (σ %.3f)\n",
                d.width, T, strings.width_m, strings.thickness, sections.width_m, sections.thickness,
                sections.sigma_thickness);
    EXPECT_EQ(strings.thickness, 1.0);  // without sections or silhouettes the thickness stays
    EXPECT_EQ(strings.sections, 0);
    EXPECT_GT(sections.sections, 0) << "the sections pooled are counted";
    EXPECT_LT(sections.sigma_thickness, 0.6 * ShapeEstimatorParams{}.prior_sigma_thickness) << T;
    // From 17–25 % off to within 8 % (measured: +6.8 % and +5.9 %, the sections' bias above).
    EXPECT_LT(std::abs(r_sections / r_true - 1), 0.08) << T;
    EXPECT_LT(std::abs(r_sections - r_true), 0.5 * std::abs(d.width - r_true)) << T;
  }
}

// Sections whose edges lie on a neighbouring finger are left out (digit_section_clear_edges): a
// hand of the model's sizes and digits whose index and ring fingers lean on the middle one (their
// abduction past the model's limits, as a finger seen partly behind its neighbour in the holding
// hand of the demo, docs/measurements.md session 49). Their sections across the middle finger read
// it wide and pulled the width × thickness up; with the gate the estimate stays near the truth.
TEST(ShapeEstimator, SectionsWithAnEdgeOnANeighbourAreLeftOut) {
  for (const double sign : {1.0, -1.0}) {
    hand::HandModel truth = hand::default_hand_model(hand::Side::kRight);
    for (const int i : {hand::kIndexMcpAbduction, hand::kRingMcpAbduction}) {
      truth.limits.lower[i] = -1.0;
      truth.limits.upper[i] = 1.0;
    }
    hand::HandParams base = nearly_straight_hand();
    base[hand::kIndexMcpAbduction] += sign * 0.3;
    base[hand::kRingMcpAbduction] -= sign * 0.3;
    // The capsules' radius scale (width × thickness) relative to the truth's, less 1.
    const double r_true = truth.shape.dimensions.width * truth.shape.dimensions.thickness;
    auto radius_error = [&](bool clear) {
      ShapeEstimatorParams sp;
      sp.digit_section_clear_edges = clear;
      const ShapeEstimate e = estimate_with_sections(truth, base, sp);
      return e.width_m * e.thickness / r_true - 1;
    };
    const double all = radius_error(false), clear = radius_error(true);
    std::printf("sign %+.0f: width × thickness %+.1f %% off with every section, %+.1f %% with the clear ones\n", sign,
                100 * all, 100 * clear);
    // Measured: +8.6 / +6.2 % with every section, +4.1 / +3.6 % with the clear ones (the rest is
    // the strings': the fit cannot lean its fingers past their limits).
    const double e_all = std::abs(all);
    const double e_clear = std::abs(clear);
    EXPECT_LT(e_clear, 0.7 * e_all) << sign;
    EXPECT_LT(e_clear, 0.05) << sign;
  }
}

// A re-estimate keeps the sizes of the lowest objective it visited: a Gauss-Newton step on the
// sizes that raises it (J_β linearises the keyframes' re-fitted poses, and the joint-balls' rows
// are left out of the width's column) is halved back instead of being followed. In the demo the
// right hand's width otherwise ran to its +15 % bound in the regrasps and the releases, the
// objective rising with every step (docs/measurements.md, 2026-11-26, late night). Hands far from the
// model's sizes, with and without the joint-balls, each solve checked.
TEST(ShapeEstimator, AReEstimateKeepsTheLowestObjectiveItVisited) {
  int rejected = 0;
  for (const auto& [L, W] : {std::pair{0.171, 0.0935}, std::pair{0.209, 0.0765}, std::pair{0.171, 0.0765}})
    for (const bool balls : {false, true}) {
      const Outcome o = run(L, W, 200, 5, ShapeSilhouette::kNone, 1.0, balls);
      std::printf("L %.3f W %.4f balls %d: L %.4f W %.4f, %d solves, %d steps halved back, objective rise max %.3g\n",
                  L, W, balls, o.estimate.length_m, o.estimate.width_m, o.estimate.solves,
                  o.estimate.steps_rejected, o.objective_rise_max);
      ASSERT_GE(o.estimate.solves, 5);
      EXPECT_LE(o.objective_rise_max, 0.0) << L << ", " << W << ", balls " << balls;
      EXPECT_LE(o.estimate.objective, o.estimate.objective_start);
      EXPECT_GE(o.estimate.objective, 0.0);
      rejected += o.estimate.steps_rejected;
    }
  EXPECT_GT(rejected, 0);  // the case this guards against occurs here
}

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

// Both hands of one person share one estimate (ShapeEstimatorParams::shared_hands): the hand that
// offers no keyframes (the pipeline's left hand holding the cube, its fingers hidden) takes the
// sizes the other's keyframes give, in the ratio of the two starting profiles. Against an
// independent reference: an estimator of the right hand alone, fed the same frames.
TEST(ShapeEstimator, BothHandsShareOneEstimateInTheirProfilesRatio) {
  const hand::HandModel left = hand::default_hand_model(hand::Side::kLeft);
  const hand::HandModel right = hand::default_hand_model(hand::Side::kRight);
  const hand::HandModel truth = resized(right, 0.205, 0.088).value();
  const hand::HandParams base = test::reaching_hands(0)[1];
  // Equal starting profiles: the shared estimate is the right hand's own, bit for bit. (solve_every
  // counts a hand's keyframes, so an estimate of both waits for twice as many; fed by one hand,
  // it is given half the count to re-estimate when the other does.)
  ShapeEstimatorParams half;
  half.solve_every = ShapeEstimatorParams{}.solve_every / 2;
  ShapeEstimator both(std::array<hand::HandModel, 2>{left, right}, half), alone(right, {});
  ASSERT_EQ(both.hands(), 2);
  const Outcome b = feed(both, 1, truth, base, 200, 5);
  const Outcome a = feed(alone, 0, truth, base, 200, 5);
  std::printf("right alone L %.4f W %.4f (%d solves); shared: left L %.4f W %.4f, right L %.4f W %.4f\n",
              a.estimate.length_m, a.estimate.width_m, a.estimate.solves, both.estimate(0).length_m,
              both.estimate(0).width_m, b.estimate.length_m, b.estimate.width_m);
  EXPECT_GE(a.estimate.solves, 1);
  EXPECT_EQ(b.estimate.length_m, a.estimate.length_m);
  EXPECT_EQ(b.estimate.width_m, a.estimate.width_m);
  EXPECT_EQ(b.estimate.solves, a.estimate.solves);
  EXPECT_GT(a.estimate.length_m, 0.19 + 0.5 * (0.205 - 0.19));  // it learnt something
  // The left hand offered nothing and has the same sizes; its model is rebuilt at them.
  EXPECT_EQ(both.estimate(0).keyframes, 0);
  EXPECT_EQ(both.estimate(1).keyframes, a.estimate.keyframes);
  EXPECT_EQ(both.estimate(0).length_m, a.estimate.length_m);
  EXPECT_NEAR(both.model(0).shape.dimensions.length, a.estimate.length_m, 1e-12);
  EXPECT_EQ(both.model(0).side, hand::Side::kLeft);
  // Different profiles (a user who measured a larger right hand): the ratio is kept.
  const hand::HandModel right_big = resized(right, 0.2, 0.09).value();
  ShapeEstimator both2(std::array<hand::HandModel, 2>{left, right_big}, {});
  feed(both2, 1, resized(right, 0.215, 0.095).value(), base, 200, 5);
  const ShapeEstimate e0 = both2.estimate(0), e1 = both2.estimate(1);
  EXPECT_GE(e1.solves, 1);
  EXPECT_NE(e1.length_m, 0.2);
  EXPECT_NEAR(e0.length_m / e1.length_m, 0.19 / 0.2, 1e-12);
  EXPECT_NEAR(e0.width_m / e1.width_m, 0.085 / 0.09, 1e-12);
  EXPECT_NEAR(e0.sigma_length_m / e1.sigma_length_m, 0.19 / 0.2, 1e-12);
  EXPECT_NEAR(both2.model(0).shape.dimensions.length, e0.length_m, 1e-12);
  EXPECT_NEAR(both2.model(1).shape.dimensions.length, e1.length_m, 1e-12);
  // A hand index outside the estimator offers nothing.
  HandObservation obs;
  EXPECT_FALSE(both2.add_frame(2, base, obs, ImageEvidence{}, RegistrationParams{}));
  EXPECT_FALSE(alone.add_frame(1, base, obs, ImageEvidence{}, RegistrationParams{}));
}

// With a camera, a frame whose bracelet was not found is not a keyframe: four fingertips alone
// are reached by a longer or shorter hand alike.
TEST(ShapeEstimator, AFrameWithoutTheBraceletsWristIsNoKeyframe) {
  const hand::HandModel right = hand::default_hand_model(hand::Side::kRight);
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandParams q = test::reaching_hands(0)[1];
  HandObservation obs = test::exact_caps(right, q);
  ImageEvidence image;
  image.camera = &camera;
  ShapeEstimator est(right, {});
  EXPECT_FALSE(est.add_frame(q, obs, image, RegistrationParams{}));
  EXPECT_EQ(est.estimate().keyframes, 0);
  obs.wrist_px = Vec2(std::nan(""), 240.0);
  est.add_frame(q, obs, image, RegistrationParams{});
  EXPECT_EQ(est.estimate().keyframes, 0);
  obs.wrist_px = camera.project(q.p_W_wrist());
  obs.wrist_confidence = 0;
  est.add_frame(q, obs, image, RegistrationParams{});
  EXPECT_EQ(est.estimate().keyframes, 0);
  obs.wrist_confidence = 0.8;
  est.add_frame(q, obs, image, RegistrationParams{});
  EXPECT_EQ(est.estimate().keyframes, 1);  // the test can fail: the gate would keep every frame out
}

// Started at the true sizes, with data from the model's own skeleton (so the truth is the
// objective's minimum), the estimate should stay there; it drifts long, because each keyframe's
// pose is re-fitted with a prior toward where the fits made with earlier sizes put it
// (ShapeEstimatorParams::keyframe_prior_scale). A wider prior drifts less.
// (The estimate following its window of keyframes: ShapeEstimatorParams::accumulate off.)
TEST(ShapeEstimator, AWiderKeyframePriorDriftsLessFromTheTruth) {
  ShapeEstimatorParams window;
  window.accumulate = false;
  ShapeEstimatorParams wide = window;
  wide.keyframe_prior_scale = 10.0;
  const double drift_1 = drift_from_the_truth(window, "keyframe prior ×1");
  const double drift_10 = drift_from_the_truth(wide, "keyframe prior ×10");
  EXPECT_LT(std::abs(drift_10), std::abs(drift_1));
}

// The same walk with the session's evidence accumulated (the default): the keyframes that left
// the window hold the length where all the poses put it, and its walk along the strings' flat
// side stops (measured 2026-11-29: −0.8 % against +14.4 % for the window alone). Not the width's:
// these keyframes see it through the strings alone, and the information they hand on was taken
// with their poses' prior where the earlier sizes' fits put them (kLast), so it ends +11.8 % wide
// (the window alone: −0.6 %; kTaken +8 %). In the demo the digits' sections see the width too
// (docs/measurements.md, session 50).
TEST(ShapeEstimator, AccumulatedEvidenceStopsTheLengthsWalk) {
  ShapeEstimatorParams window;
  window.accumulate = false;
  const double drift_window = drift_from_the_truth(window, "window");
  const double drift_all = drift_from_the_truth({}, "accumulated");
  EXPECT_LT(std::abs(drift_all), 0.02);
  EXPECT_LT(std::abs(drift_all), 0.5 * std::abs(drift_window));
}

// The same start at the truth with the keyframes' prior kept where each frame's fit put it
// (KeyframePrior::kTaken): the truth stays a fixed point of the estimate.
TEST(ShapeEstimator, APriorAtTheTakenPoseKeepsTheTruthAFixedPoint) {
  ShapeEstimatorParams last;
  last.accumulate = false;  // the window alone (accumulated, both stay near the truth)
  ShapeEstimatorParams taken = last;
  taken.keyframe_prior = KeyframePrior::kTaken;
  const double drift_last = drift_from_the_truth(last, "keyframe prior at the last pose");
  const double drift_taken = drift_from_the_truth(taken, "keyframe prior at the taken pose");
  EXPECT_LT(std::abs(drift_taken), 0.01);  // measured 2026-11-25: +0.25 % (kLast: +13.6 %)
  EXPECT_LT(std::abs(drift_taken), std::abs(drift_last));
}

// KeyframeWindow::kSession keeps a uniform sample of every pose offered (reservoir sampling):
// after n candidates it has kept about K (1 + ln(n / K)) of them, not n, so its re-estimates
// (one per solve_every keyframes kept) come ever rarer; kNewest keeps every one. Both estimate
// finite sizes near the truth's, and a replay of the same frames draws the same sample.
TEST(ShapeEstimator, TheSessionWindowKeepsAUniformSampleOfThePoses) {
  const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), 0.1976, 0.0825).value();
  ShapeEstimatorParams newest, session;
  newest.digit_section_sigma = session.digit_section_sigma = 0.0;
  newest.keyframes = session.keyframes = 8;
  newest.solve_every = session.solve_every = 4;
  session.keyframe_window = KeyframeWindow::kSession;
  ShapeEstimator a(hand::default_hand_model(hand::Side::kRight), newest);
  ShapeEstimator b(hand::default_hand_model(hand::Side::kRight), session);
  ShapeEstimator c(hand::default_hand_model(hand::Side::kRight), session);
  const Outcome oa = feed(a, 0, truth, test::reaching_hands(0)[1], 300, 7);
  const Outcome ob = feed(b, 0, truth, test::reaching_hands(0)[1], 300, 7);
  const Outcome oc = feed(c, 0, truth, test::reaching_hands(0)[1], 300, 7);
  std::printf("solves: newest %d, session %d; widths %.4f, %.4f (truth 0.0825)\n", oa.estimate.solves,
              ob.estimate.solves, oa.estimate.width_m, ob.estimate.width_m);
  EXPECT_EQ(ob.estimate.keyframes, 8);
  EXPECT_LT(ob.estimate.solves, oa.estimate.solves / 2);
  EXPECT_GE(ob.estimate.solves, 2);
  EXPECT_NEAR(ob.estimate.width_m, 0.0825, 0.0825 * 0.15);
  EXPECT_NEAR(ob.estimate.length_m, 0.1976, 0.1976 * 0.15);
  EXPECT_EQ(ob.estimate.width_m, oc.estimate.width_m);  // deterministic
  EXPECT_EQ(ob.estimate.solves, oc.estimate.solves);
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
  EXPECT_EQ(p.max_fingertip_cost, d.max_fingertip_cost);
  EXPECT_EQ(p.max_keyframe_speed_m_s, d.max_keyframe_speed_m_s);
  EXPECT_EQ(p.apply_after_frames, 15);  // the sessions re-estimate on a thread of their own
  EXPECT_EQ(p.shared_hands, d.shared_hands);
  EXPECT_EQ(p.keyframe_prior_scale, d.keyframe_prior_scale);
  EXPECT_EQ(p.keyframe_prior, d.keyframe_prior);
  EXPECT_EQ(p.keyframe_window, d.keyframe_window);
  EXPECT_EQ(p.joint_balls, d.joint_balls);
  EXPECT_EQ(p.palm_breadth_sigma_px, d.palm_breadth_sigma_px);
  EXPECT_EQ(p.palm_chord.at, d.palm_chord.at);
  EXPECT_EQ(p.palm_chord.min_facing, d.palm_chord.min_facing);
  EXPECT_EQ(p.digit_axes, d.digit_axes);
  EXPECT_EQ(p.digit_section_sigma, d.digit_section_sigma);
  EXPECT_EQ(p.digit_section_clear_edges, d.digit_section_clear_edges);
  EXPECT_EQ(p.accumulate, d.accumulate);
  EXPECT_EQ(p.cap_offset_from_image, d.cap_offset_from_image);
  EXPECT_EQ(p.cap_offset_min_samples, d.cap_offset_min_samples);
  EXPECT_EQ(p.cap_offset_max_change_m, d.cap_offset_max_change_m);
  expect_parse_error("personalisation:\n  min_pose_change: -1\n", "bad.yaml", "min_pose_change");
  for (const std::string key :
       {"apply_after_frames", "reach_min_miss_m", "max_fingertip_cost", "keyframe_prior_scale"})
    expect_parse_error("personalisation:\n  " + key + (key == "reach_min_miss_m" ? ": 0.5\n" : ": -1\n"),
                       "bad.yaml", key);
  const auto on = core::ConfigNode::Parse(
      "personalisation:\n  silhouette: spill\n  reach_min_miss_m: 0\n  prior_sigma_thickness: 0.2\n"
      "  max_fingertip_cost: 25\n  shared_hands: false\n  keyframe_prior_scale: 10\n"
      "  keyframe_prior: taken\n  joint_balls: true\n  keyframe_window: session\n"
      "  digit_section_clear_edges: false\n  accumulate: true\n  cap_offset_from_image: true\n"
      "  cap_offset_min_samples: 25\n  cap_offset_max_change_m: 0.002\n", "on.yaml");
  const ShapeEstimatorParams q = parse_shape_estimator_params(on["personalisation"], &enabled);
  EXPECT_EQ(q.silhouette, ShapeSilhouette::kSpill);
  EXPECT_EQ(q.reach_min_miss_m, 0.0);
  EXPECT_EQ(q.prior_sigma_thickness, 0.2);
  EXPECT_EQ(q.max_fingertip_cost, 25.0);
  EXPECT_FALSE(q.shared_hands);
  EXPECT_EQ(q.keyframe_prior_scale, 10.0);
  EXPECT_EQ(q.keyframe_prior, KeyframePrior::kTaken);
  EXPECT_FALSE(q.digit_section_clear_edges);
  EXPECT_TRUE(q.accumulate);
  EXPECT_TRUE(q.cap_offset_from_image);
  EXPECT_EQ(q.cap_offset_min_samples, 25);
  EXPECT_EQ(q.cap_offset_max_change_m, 0.002);
  EXPECT_EQ(q.keyframe_window, KeyframeWindow::kSession);
  EXPECT_TRUE(q.joint_balls);
  EXPECT_EQ(p.silhouette, ShapeSilhouette::kNone);  // the shipped setting
  // An unknown choice names the file, line, key and the choices.
  expect_parse_error("personalisation:\n  silhouette: inward\n", "typo.yaml", "none, spill or both");
  expect_parse_error("personalisation:\n  keyframe_prior: first\n", "where.yaml", "taken or last");
  expect_parse_error("personalisation:\n  keyframe_window: all\n", "window.yaml", "newest or session");
  expect_parse_error("personalisation:\n  shared_hands: sometimes\n", "maybe.yaml", "shared_hands");
  expect_parse_error("personalisation:\n  joint_balls: 3\n", "balls.yaml", "joint_balls");
  expect_parse_error("personalisation:\n  digit_axes: often\n", "axes.yaml", "digit_axes");
  expect_parse_error("personalisation:\n  accumulate: always\n", "acc.yaml", "accumulate");
  expect_parse_error("personalisation:\n  cap_offset_from_image: maybe\n", "cap.yaml", "cap_offset_from_image");
  expect_parse_error("personalisation:\n  cap_offset_min_samples: 0\n", "cap.yaml", "cap_offset_min_samples");
  expect_parse_error("personalisation:\n  cap_offset_max_change_m: 0.05\n", "cap.yaml", "cap_offset_max_change_m");
  expect_parse_error("personalisation:\n  palm_breadth_at: 1.5\n", "at.yaml", "palm_breadth_at");
  expect_parse_error("personalisation:\n  palm_breadth_min_facing: -0.1\n", "f.yaml", "palm_breadth_min_facing");
  expect_parse_error("personalisation:\n  palm_breadth_sigma_px: -2\n", "s.yaml", "palm_breadth_sigma_px");
  const auto chords = core::ConfigNode::Parse(
      "personalisation:\n  palm_breadth_sigma_px: 3\n  palm_breadth_at: 0.7\n  palm_breadth_min_facing: 0.6\n",
      "chords.yaml");
  const ShapeEstimatorParams c = parse_shape_estimator_params(chords["personalisation"], &enabled);
  EXPECT_EQ(c.palm_breadth_sigma_px, 3.0);
  EXPECT_EQ(c.palm_chord.at, 0.7);
  EXPECT_EQ(c.palm_chord.min_facing, 0.6);
  // The digits' sections' σ: 0 is off, a tiny one no measurement; numbers as written.
  expect_parse_error("personalisation:\n  digit_section_sigma: 1e-200\n", "sec.yaml",
                     "personalisation.digit_section_sigma: expected 0 (off) or a value in (0.001, 2], got 1e-200");
  expect_parse_error("personalisation:\n  prior_sigma_width_m: 1e-300\n", "tiny.yaml",
                     "expected a value in (1e-05, 0.1], got 1e-300");
  expect_parse_error("personalisation:\n  max_relative_change: 5\n", "big.yaml",
                     "expected a value in (0, 0.5], got 5");
  // The keyframes' speed gate [m/s]: 0 is off; no negative or absurd speed.
  const auto gate = core::ConfigNode::Parse("personalisation:\n  max_keyframe_speed_m_s: 0.1\n", "gate.yaml");
  EXPECT_EQ(parse_shape_estimator_params(gate["personalisation"], &enabled).max_keyframe_speed_m_s, 0.1);
  expect_parse_error("personalisation:\n  max_keyframe_speed_m_s: -0.1\n", "gate.yaml",
                     "personalisation.max_keyframe_speed_m_s: expected a value in [0, 100], got -0.1");
  expect_parse_error("personalisation:\n  max_keyframe_speed_m_s: 1e9\n", "gate.yaml", "max_keyframe_speed_m_s");
  const auto sections = core::ConfigNode::Parse("personalisation:\n  digit_section_sigma: 0.15\n", "sec.yaml");
  EXPECT_EQ(parse_shape_estimator_params(sections["personalisation"], &enabled).digit_section_sigma, 0.15);
  // An estimate that could never start (more keyframes needed than kept) is refused.
  expect_parse_error("personalisation:\n  min_keyframes: 100\n  keyframes: 24\n", "never.yaml",
                     "min_keyframes (100) must not exceed keyframes (24)");
}

}  // namespace
}  // namespace spidar::registration
