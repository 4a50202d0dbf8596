// Convergence from perturbed poses on synthetic frames: the simulated camera films the user's
// true hands ("user" profile of configs/hands.yaml: 4 % longer, 3 % narrower than the model,
// their own anatomical mesh, sim/anatomical_hand.hpp) as skin over a blue screen with red
// bracelets; chroma key,
// bracelet detection and the distance transform run on that image; the registration fits the
// default model hands to it and to string fingertips with 0.5 mm noise.
//
// Bounds. The model hand is not the user's hand, so even a perfect fit leaves projected joints
// off: at the true parameters the model's joints are 5.9 px and its caps 6.2 mm from the truth.
// Measured on 2026-11-24 (the wrist term comparing the bracelet's midpoint with the band's visible
// surface, registration_params.hpp): from ±1.5 cm / ±0.15 rad / ±0.2 rad starts (8 seeds × 2
// hands) paper's terms 21.5 → 1.4 mm, 19.8 → 4.6 px mean, worst 2.0 mm / 5.8 px. The hand-aware
// silhouette term (coverage.hpp; measured 2026-11-24, the owners decided at the starts, then once
// more at the first fit, as a tracker's next frame does): 1.37 mm / 4.45 px, worst 2.0 mm / 5.6
// px; from ±2 cm / 0.2 / 0.3 rad 1.35 mm / 4.4 px, worst 5.8 px (7.75 px with one round: the
// owners decided 2 cm off). A fit started at the truth settles at 1.45 mm / 5.1 px (worst 6.0
// px; silhouette 1.4 mm / 4.1 px, worst 5.3 px). The bounds (3 mm and 7 px per fit, 2 mm and
// 5 px mean, 6.5 px from the truth) leave ~1 px over the measured fits.
//
// The truth's little finger copies the ring's angles here (reaching_hands), so the fits keep the
// paper's little finger (little_free false): a free one (the default, registration_params.hpp)
// costs on such a truth, measured 2026-11-26 from ±2 cm / 0.2 / 0.3 rad: 4.05 → 4.94 px mean,
// worst 5.8 → 7.75 px (4.45 px, worst 5.9 at σ 0.12 rad): the ring loses the little finger's
// evidence. A little finger off the ring's angles is test_little_finger.cpp's.
#include <gtest/gtest.h>

#include <cstdio>

#include "registration_test_util.hpp"
#include "spidar/registration/metrics.hpp"

namespace spidar::registration {
namespace {

struct Stats {
  double tip_before_mm = 0, tip_after_mm = 0, px_before = 0, px_after = 0;
  double worst_tip_after_mm = 0, worst_px_after = 0;
  int fits = 0, not_improved = 0;
};

struct Scene {
  std::array<hand::HandModel, 2> truth_models = test::truth_models();
  std::array<hand::HandModel, 2> models = test::model_hands();
  vision::Camera camera = vision::default_rig_camera();
  std::array<hand::HandParams, 2> truth = test::reaching_hands();
  test::FrameEvidence ev;
  ImageEvidence image;
};

void film(Scene* s) {
  auto cam = sim::SyntheticCamera::create(*test::gl().context, s->camera, s->truth_models);
  ASSERT_TRUE(cam.ok()) << cam.error().message;
  test::film_and_key(**cam, s->truth, &s->ev);
  for (int h = 0; h < 2; ++h) ASSERT_TRUE(s->ev.bracelets[h].found) << "hand " << h;
  s->image.camera = &s->camera;
  s->image.alpha = s->ev.key.alpha;
  s->image.distance = &s->ev.distance;
}

// Fits both hands from perturbed starts (prior = the start, as a tracker's previous frame).
Stats run(const Scene& sc, const RegistrationParams& params, const std::vector<std::uint32_t>& seeds,
          double wrist_m, double rot, double joint) {
  const SuccessiveAdjustment solver(params);
  Stats s;
  for (std::uint32_t seed : seeds) {
    std::mt19937 rng(seed);
    std::array<HandObservation, 2> observed;
    std::array<hand::HandParams, 2> starts;
    for (int h = 0; h < 2; ++h) {
      observed[h] = test::observe(sc.truth_models[h], sc.truth[h], sc.ev.bracelets[h], rng);
      starts[h] = test::perturb(sc.truth[h], sc.models[h], rng, wrist_m, rot, joint);
    }
    // The silhouette pixels each hand owns, decided at the starts as a tracker decides them at
    // the previous frame's fits. With the silhouette term the fit runs twice, the second time
    // with the owners decided at the first fit's result (what the next frame of a tracker does).
    std::array<hand::HandParams, 2> fitted = starts;
    std::array<FitReport, 2> reports;
    for (int round = 0; round < (params.silhouette_term ? 2 : 1); ++round) {
      const auto owned = test::owned_pixels(sc.ev.key.silhouette, sc.models, fitted, sc.camera, params);
      for (int h = 0; h < 2; ++h) {
        ImageEvidence image = sc.image;
        image.coverage = &owned[h];
        hand::HandParams q = round == 0 ? starts[h] : fitted[h];
        reports[h] = solver.fit(sc.models[h], observed[h], image, &starts[h], &q);
        fitted[h] = q;
      }
    }
    for (int h = 0; h < 2; ++h) {
      const hand::HandParams& start = starts[h];
      const hand::HandParams& q = fitted[h];
      const FitReport& rep = reports[h];
      EXPECT_TRUE(q.q.allFinite());
      EXPECT_TRUE(hand::within_limits(q, sc.models[h].limits));
      EXPECT_GT(rep.iterations, 0);
      const hand::HandPoints t = hand::forward_kinematics(sc.truth_models[h], sc.truth[h]);
      const hand::HandPoints a = hand::forward_kinematics(sc.models[h], start);
      const hand::HandPoints b = hand::forward_kinematics(sc.models[h], q);
      const double tb = 1e3 * fingertip_error_m(a, t), ta = 1e3 * fingertip_error_m(b, t);
      const double pb = joint_px_error(a, t, sc.camera), pa = joint_px_error(b, t, sc.camera);
      s.tip_before_mm += tb;
      s.tip_after_mm += ta;
      s.px_before += pb;
      s.px_after += pa;
      s.worst_tip_after_mm = std::max(s.worst_tip_after_mm, ta);
      s.worst_px_after = std::max(s.worst_px_after, pa);
      s.not_improved += (ta >= tb || pa >= pb) ? 1 : 0;
      ++s.fits;
    }
  }
  s.tip_before_mm /= s.fits;
  s.tip_after_mm /= s.fits;
  s.px_before /= s.fits;
  s.px_after /= s.fits;
  return s;
}

void print(const char* name, const Stats& s) {
  std::printf("%-22s fingertip %.2f -> %.2f mm (worst %.2f), joints %.1f -> %.2f px (worst %.2f), "
              "%d fits\n",
              name, s.tip_before_mm, s.tip_after_mm, s.worst_tip_after_mm, s.px_before, s.px_after,
              s.worst_px_after, s.fits);
}

const std::vector<std::uint32_t> kSeeds{1, 2, 3, 4, 5, 6, 7, 8};

void expect_converged(const Stats& s) {
  EXPECT_EQ(s.not_improved, 0);
  EXPECT_LT(s.worst_tip_after_mm, 3.0);
  EXPECT_LT(s.worst_px_after, 7.0);
  EXPECT_LT(s.px_after, 5.0);
  EXPECT_LT(s.tip_after_mm, 2.0);
}

TEST(Convergence, PaperTermsFromPerturbedStarts) {
  SPIDAR_SKIP_WITHOUT_GL();
  Scene sc;
  film(&sc);
  const Stats s = run(sc, RegistrationParams{}, kSeeds, 0.015, 0.15, 0.2);
  print("paper terms", s);
  expect_converged(s);
}

TEST(Convergence, JointBallsAndSilhouetteFromPerturbedStarts) {
  SPIDAR_SKIP_WITHOUT_GL();
  Scene sc;
  film(&sc);
  RegistrationParams p;
  p.silhouette_term = true;
  p.little_free = false;
  const Stats s = run(sc, p, kSeeds, 0.015, 0.15, 0.2);
  print("balls + silhouette", s);
  expect_converged(s);
}

TEST(Convergence, LargerStartErrorsWithMoreIterations) {
  SPIDAR_SKIP_WITHOUT_GL();
  Scene sc;
  film(&sc);
  RegistrationParams p;
  p.silhouette_term = true;
  p.little_free = false;
  p.max_iterations = 20;
  const Stats s = run(sc, p, kSeeds, 0.02, 0.2, 0.3);
  print("2 cm / 0.2 rad / 0.3 rad", s);
  expect_converged(s);
}

TEST(Convergence, FromTheTruthStaysAtTheFloor) {
  SPIDAR_SKIP_WITHOUT_GL();
  Scene sc;
  film(&sc);
  for (bool sil : {false, true}) {
    RegistrationParams p;
    p.silhouette_term = sil;
    p.little_free = false;
    const Stats s = run(sc, p, {1, 2, 3}, 0.0, 0.0, 0.0);
    print(sil ? "from truth, silhouette" : "from truth, paper", s);
    EXPECT_LT(s.worst_tip_after_mm, 2.0);
    EXPECT_LT(s.worst_px_after, 6.5);
  }
}

TEST(Convergence, WithoutImageOnlyTheStringsAndThePriorAct) {
  SPIDAR_SKIP_WITHOUT_GL();
  Scene sc;
  film(&sc);
  sc.image = ImageEvidence{};  // no camera: fingertips and prior only
  const Stats s = run(sc, RegistrationParams{}, {1, 2, 3}, 0.015, 0.15, 0.2);
  print("no image", s);
  EXPECT_EQ(s.not_improved, 0);
  EXPECT_LT(s.worst_tip_after_mm, 3.0);
}

}  // namespace
}  // namespace spidar::registration
