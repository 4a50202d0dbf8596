// The full residual Jacobian (every term, targets frozen) against central finite differences of
// the residual vector.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "registration_test_util.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

struct Case {
  hand::HandModel model;
  hand::HandParams truth, q, prior;
  HandObservation obs;
  vision::Camera camera = vision::default_rig_camera();
  test::MaskEvidence mask;
  RegistrationParams params;
  std::vector<OwnedPixel> owned;  ///< silhouette pixels of this hand (coverage.hpp)
};

// The true hand draws the silhouette; the evaluation pose q is a perturbation of it, so that
// every term has rows (balls near edges, silhouette points outside, nonzero prior).
void make_case(int side, std::uint32_t seed, Case* c) {
  const auto models = test::model_hands();
  c->model = models[side];
  c->truth = test::reaching_hands()[side];
  std::mt19937 rng(seed);
  c->q = test::perturb(c->truth, c->model, rng, 0.01, 0.08, 0.15);
  c->prior = test::perturb(c->truth, c->model, rng);
  cv::Mat m;
  test::draw_capsule_mask(c->model, c->truth, c->camera, &m);
  test::evidence_from_mask(m, &c->mask);
  vision::BraceletObservation b;
  b.found = true;
  b.wrist_px = c->camera.project(c->truth.p_W_wrist()) + Vec2(3, -2);
  b.confidence = 0.8;
  c->obs = test::observe(c->model, c->truth, b, rng, 0.001);
  c->params.silhouette_term = true;
  c->params.silhouette_inward = true;
  c->params.silhouette_samples_per_bone = 4;
  c->params.digit_axis_sigma_px = 5.0;
  // No other hand: this one owns its silhouette, decided at the truth.
  ProjectedHand outline;
  project_hand(c->model, c->truth, c->camera, 0.03, &outline);
  std::array<std::vector<OwnedPixel>, 2> owned;
  coverage_evidence(m, {&outline, nullptr}, c->params, &owned);
  c->owned = owned[0];
}

TEST(ResidualJacobian, MatchesCentralDifferences) {
  int palm_points = 0;  // coverage points held by the palm box, over all cases
  int axis_points = 0;  // digit axis sections (digit_axis_sigma_px), over all cases
  for (int side = 0; side < 2; ++side) {
    for (std::uint32_t seed : {1u, 2u, 3u, 4u}) {
      Case c;
      make_case(side, seed, &c);
      if (seed >= 3) {
        // A little finger of its own (registration's little_free): its columns, its prior (seed
        // 3: from a prior whose little finger copied the ring; 4: its own) and the coupling rows.
        c.params.little_free = true;
        c.q.little_independent = true;
        c.q.set_little(c.q.ring() + Vec3(0.2, -0.05, 0.1));
        if (seed == 4) {
          c.prior.little_independent = true;
          c.prior.set_little(c.prior.ring() + Vec3(-0.1, 0.05, 0.15));
        }
      }
      if (seed % 2 == 0) {
        // The band's length (bracelet_length_sigma): its row, off the length at q.
        c.params.bracelet_length_sigma = 0.1;
        c.obs.wrist_length_px =
            1.3 * bracelet_length_px(hand::hand_pose(c.q), c.model.shape.dimensions.width, c.camera, c.params);
        // And its thickness (bracelet_thickness_sigma) across the band's projected long axis.
        c.params.bracelet_thickness_sigma = 0.1;
        const auto ends = bracelet_band_ends(hand::hand_pose(c.q), c.model.shape.dimensions.width,
                                             c.camera.X_WC().p, c.params);
        c.obs.wrist_axis_px = (c.camera.project(ends[1]) - c.camera.project(ends[0])).normalized();
        const Vec2 across(-c.obs.wrist_axis_px.y(), c.obs.wrist_axis_px.x());
        c.obs.wrist_thickness_px = 0.7 * bracelet_band_thickness(hand::hand_pose(c.q), c.model.shape.dimensions.width,
                                                                 c.camera, c.params, across);
        ASSERT_GT(c.obs.wrist_thickness_px, 1.0);
      }
      // A bent wrist (HandObservation::forearm_H): the bracelet sits along the forearm.
      if (seed == 3) c.obs.forearm_H = Vec3(0.4, -0.8, 0.45).normalized();
      ImageEvidence image = c.mask.evidence(&c.camera, true);
      image.coverage = &c.owned;
      const ResidualProblem pr{&c.model, &c.obs, &image, &c.prior, &c.params};
      FrozenTargets tg;
      freeze_targets(pr, c.q, &tg);
      EXPECT_EQ(tg.band_active, seed % 2 == 0);
      EXPECT_EQ(tg.thickness_active, seed % 2 == 0);
      // Every term is present.
      const TermCosts costs = term_costs(pr, tg, c.q);
      EXPECT_GT(costs.fingertip, 0.0);
      EXPECT_GT(costs.wrist, 0.0);
      EXPECT_GT(costs.joint_ball, 0.0) << "side " << side << " seed " << seed;
      EXPECT_GT(costs.silhouette, 0.0);
      EXPECT_GT(costs.prior, 0.0);
      if (seed == 3) {  // the bent forearm moved the wrist term's point
        HandObservation in_line = c.obs;
        in_line.forearm_H = Vec3(0.0, -1.0, 0.0);
        const ResidualProblem pr_in_line{&c.model, &in_line, &image, &c.prior, &c.params};
        FrozenTargets tg_in_line;
        freeze_targets(pr_in_line, c.q, &tg_in_line);
        EXPECT_GT(std::abs(term_costs(pr_in_line, tg_in_line, c.q).wrist - costs.wrist), 1e-3 * costs.wrist);
      }
      EXPECT_GT(tg.silhouette_count, 5);
      EXPECT_GT(tg.coverage_count, 5) << "side " << side << " seed " << seed;
      axis_points += tg.axis_count;
      for (int k = 0; k < tg.coverage_count; ++k) palm_points += tg.coverage[k].bone < 0 ? 1 : 0;

      VecX r;
      MatX J;
      std::vector<ResidualTerm> terms;
      stacked_residuals(pr, tg, c.q, &r, &J, &terms);
      ASSERT_EQ(J.rows(), r.size());
      EXPECT_EQ(std::count(terms.begin(), terms.end(), ResidualTerm::kBand), seed % 2 == 0 ? 2 : 0);
      EXPECT_NEAR(r.squaredNorm(), costs.total(), 1e-9 * costs.total());
      MatX J_fd(J.rows(), J.cols());
      const double h = 1e-6;
      for (int i = 0; i < hand::kParamCount; ++i) {
        hand::HandParams qp = c.q, qm = c.q;
        qp[i] += h;
        qm[i] -= h;
        VecX rp, rm;
        stacked_residuals(pr, tg, qp, &rp, nullptr);
        stacked_residuals(pr, tg, qm, &rm, nullptr);
        ASSERT_EQ(rp.size(), r.size());
        J_fd.col(i) = (rp - rm) / (2 * h);
      }
      const double scale = std::max(1.0, J.cwiseAbs().maxCoeff());
      for (int row = 0; row < J.rows(); ++row) {
        for (int col = 0; col < J.cols(); ++col) {
          ASSERT_NEAR(J(row, col), J_fd(row, col), 2e-6 * scale)
              << "side " << side << " seed " << seed << " row " << row << " of " << J.rows()
              << ", parameter " << hand::param_name(col);
        }
      }
    }
  }
  EXPECT_GT(palm_points, 0);
  EXPECT_GT(axis_points, 5);  // the digit axes' rows were checked too
}

// What the strings and the bracelet's midpoint measure of hand `truth`, exactly: its four
// fingertips, and its wrist joint projected (the band at the wrist joint: bracelet_offset_m 0).
HandObservation exact_observation(const hand::HandModel& model, const hand::HandParams& truth,
                                  const vision::Camera& camera) {
  HandObservation obs;
  const hand::HandPoints pts = hand::forward_kinematics(model, truth);
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    obs.p_W_fingertip[f] = pts.p_W_fingertip[f];
    obs.fingertip_valid[f] = true;
  }
  obs.wrist_px = camera.project(truth.p_W_wrist());
  obs.wrist_confidence = 1.0;
  return obs;
}

// Hand `q` turned by `angle` [rad] about the line through its index and ring fingertips (which
// stay where they are): the wrist swings on a circle about them.
hand::HandParams turned_about_fingertips(const hand::HandModel& model, const hand::HandParams& q, double angle) {
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  const Vec3 pivot = pts.p_W_fingertip[hand::kIndex];
  const Mat3 turn =
      Eigen::AngleAxisd(angle, (pts.p_W_fingertip[hand::kRing] - pivot).normalized()).toRotationMatrix();
  const Eigen::AngleAxisd turned(Mat3(turn * hand::hand_pose(q).R.toRotationMatrix()));
  hand::HandParams out = q;
  out.set_wrist(pivot + turn * (q.p_W_wrist() - pivot), turned.angle() * turned.axis());
  return out;
}

// The fit from `start` with `params` (50 iterations) on `obs`, the camera known but no image: the
// strings, the bracelet's midpoint and the band's terms only.
hand::HandParams fit_image_free(const hand::HandModel& model, const HandObservation& obs,
                                const vision::Camera& camera, RegistrationParams params, hand::HandParams start) {
  params.max_iterations = 50;
  ImageEvidence image;
  image.camera = &camera;
  SuccessiveAdjustment(params).fit(model, obs, image, nullptr, &start);
  return start;
}

/// What the band tests start from: a model hand at the reaching pose, the band at the wrist joint
/// (its midpoint's ray is the wrist's), and the exact observation of that pose.
struct BandCase {
  hand::HandModel model;
  hand::HandParams truth;
  RegistrationParams params;
  HandObservation obs;
};
BandCase band_case(int side, const vision::Camera& camera) {
  BandCase c{test::model_hands()[side], test::reaching_hands()[side], {}, {}};
  c.params.bracelet_offset_m = 0.0;
  c.params.bracelet_surface_shift = 0.0;
  c.obs = exact_observation(c.model, c.truth, camera);
  return c;
}

// The band's length says how far along its ray the wrist is, which its projected midpoint cannot:
// a hand started 4 cm too deep along the ray of its bracelet's midpoint, with the fingertips from
// the strings, comes nearer its true depth with the band's length (7 mm off, against 14 mm without: a
// weak term stops within its σ).
TEST(BraceletBand, TheBandsLengthPullsAWristBackToItsDepth) {
  const vision::Camera camera = vision::default_rig_camera();
  for (int side = 0; side < 2; ++side) {
    auto [model, truth, params, obs] = band_case(side, camera);
    const double length = bracelet_length_px(hand::hand_pose(truth), model.shape.dimensions.width, camera, params);
    ASSERT_GT(length, 10.0);
    obs.wrist_length_px = length;
    hand::HandParams start = truth;
    const Vec3 ray = (truth.p_W_wrist() - camera.X_WC().p).normalized();
    start.q.segment<3>(hand::kWristX) = truth.p_W_wrist() + 0.04 * ray;
    auto depth_error = [&](double sigma) {
      RegistrationParams p = params;
      p.bracelet_length_sigma = sigma;
      p.bracelet_length_tolerance = 0.0;
      const hand::HandParams q = fit_image_free(model, obs, camera, p, start);
      return std::abs(camera.depth(q.p_W_wrist()) - camera.depth(truth.p_W_wrist()));
    };
    const double with_band = depth_error(0.05), without = depth_error(0.0);
    EXPECT_LT(with_band, 0.01) << "side " << side;  // from 0.04 (a weak term: the fit stops within its σ)
    EXPECT_LT(with_band, 0.5 * without) << "side " << side << ", without the band " << without << " m";
    std::printf("side %d: wrist depth error %.1f mm with the band, %.1f mm without\n", side, 1e3 * with_band, 1e3 * without);
  }
}

// The band's thickness against a brute-force reference: its near side sampled ten times as
// densely around each rim and on nine rings between the rims gives the same extent across the
// band's axis within 1 %; seen more obliquely (the hand turned about its fingertips), it changes.
TEST(BraceletBand, TheThicknessIsTheNearSidesExtentAcrossTheBand) {
  const auto models = test::model_hands();
  const vision::Camera camera = vision::default_rig_camera();
  const RegistrationParams params;
  for (int side = 0; side < 2; ++side) {
    const hand::HandModel& model = models[side];
    const hand::HandParams q = test::reaching_hands()[side];
    const Pose X = hand::hand_pose(q);
    const double width = model.shape.dimensions.width;
    const auto ends = bracelet_band_ends(X, width, camera.X_WC().p, params);
    const Vec2 axis = (camera.project(ends[1]) - camera.project(ends[0])).normalized();
    const Vec2 across(-axis.y(), axis.x());
    std::array<Vec3, 2> extreme;
    const double t = bracelet_band_thickness(X, width, camera, params, across, &extreme);
    ASSERT_GT(t, 5.0);
    EXPECT_NEAR((camera.project(extreme[1]) - camera.project(extreme[0])).dot(across), t, 1e-9);
    // Reference: the band's surface (not only its rims), the ellipse of bracelet_band_ends.
    const Mat3 R = X.R.toRotationMatrix();
    const double a = params.bracelet_radius_per_width * width + params.bracelet_standoff_m;
    const double b = params.bracelet_depth_ratio * params.bracelet_radius_per_width * width + params.bracelet_standoff_m;
    double lo = 1e300, hi = -1e300;
    for (int ring = 0; ring <= 10; ++ring) {
      const double along = params.bracelet_offset_m + params.bracelet_width_m * (ring / 10.0 - 0.5);
      for (int k = 0; k < 480; ++k) {
        const double phi = 2 * 3.14159265358979 * k / 480;
        const Vec3 p = X * Vec3(0, -along, 0) + a * std::cos(phi) * R.col(0) + b * std::sin(phi) * R.col(2);
        const Vec3 normal = (std::cos(phi) / a) * R.col(0) + (std::sin(phi) / b) * R.col(2);
        if (normal.dot(camera.X_WC().p - p) <= 0) continue;
        const double u = camera.project(p).dot(across);
        lo = std::min(lo, u), hi = std::max(hi, u);
      }
    }
    EXPECT_NEAR(t, hi - lo, 0.01 * (hi - lo)) << "side " << side;
    // Turned 25° about the line through its index and ring fingertips, the band looks otherwise.
    const Pose turned = hand::hand_pose(turned_about_fingertips(model, q, 0.44));
    const double t_turned = bracelet_band_thickness(turned, width, camera, params, across);
    EXPECT_GT(std::abs(t_turned / t - 1.0), 0.1) << "side " << side << ": " << t << " → " << t_turned << " px";
  }
}

// With the fingertips from the strings and the bracelet's midpoint, a hand turned 25° about its
// fingertips is held by nothing but the image; the band's thickness turns it back nearer the
// truth.
TEST(BraceletBand, TheBandsThicknessTurnsAHandBackAboutItsFingertips) {
  const vision::Camera camera = vision::default_rig_camera();
  for (int side = 0; side < 2; ++side) {
    auto [model, truth, params, obs] = band_case(side, camera);
    const Pose X = hand::hand_pose(truth);
    const auto ends = bracelet_band_ends(X, model.shape.dimensions.width, camera.X_WC().p, params);
    obs.wrist_axis_px = (camera.project(ends[1]) - camera.project(ends[0])).normalized();
    const Vec2 across(-obs.wrist_axis_px.y(), obs.wrist_axis_px.x());
    obs.wrist_thickness_px = bracelet_band_thickness(X, model.shape.dimensions.width, camera, params, across);
    ASSERT_GT(obs.wrist_thickness_px, 5.0);
    // Start: the true pose turned 25° about the line through the index and ring fingertips.
    const hand::HandParams start = turned_about_fingertips(model, truth, 0.44);
    auto angle_error = [&](double sigma) {
      RegistrationParams p = params;
      p.bracelet_thickness_sigma = sigma;
      p.bracelet_thickness_tolerance = 0.0;
      const hand::HandParams q = fit_image_free(model, obs, camera, p, start);
      return Eigen::AngleAxisd(hand::hand_pose(q).R * X.R.inverse()).angle();
    };
    // One scalar against a turn of three angles: it takes back the part it sees (measured: 0.101 →
    // 0.076 rad and 0.309 → 0.097 rad at σ 0.1; a stiffer σ stops earlier, at the dead zone's kink).
    const double with_band = angle_error(0.1), without = angle_error(0.0);
    EXPECT_LT(with_band, 0.85 * without) << "side " << side << ", without the thickness " << without << " rad";
    std::printf("side %d: hand rotation error %.3f rad with the band's thickness, %.3f rad without\n", side,
                with_band, without);
  }
}

// A size estimate (shape_estimator.hpp) differentiates the residuals with respect to the model's
// sizes at frozen targets: a silhouette point's edge must move with its capsule's radius. With the
// image terms alone (no fingertips, wrist, matte or prior) the rows are the silhouette points'
// then the coverage points', two each; with digits T times as thick, each bone point's row moves
// by (T − 1) × its frozen offset × its weight, and a palm point's not at all.
TEST(ResidualJacobian, SilhouetteEdgesMoveWithTheDigitsThickness) {
  for (int side = 0; side < 2; ++side) {
    Case c;
    make_case(side, 5, &c);
    ImageEvidence image = c.mask.evidence(&c.camera, true);
    image.alpha = cv::Mat();  // no joint-balls
    image.coverage = &c.owned;
    const HandObservation none;
    const ResidualProblem pr{&c.model, &none, &image, nullptr, &c.params};
    FrozenTargets tg;
    freeze_targets(pr, c.q, &tg);
    ASSERT_GT(tg.silhouette_count, 5);
    ASSERT_GT(tg.coverage_count, 5);
    VecX r;
    stacked_residuals(pr, tg, c.q, &r, nullptr);
    ASSERT_EQ(r.size(), 2 * (tg.silhouette_count + tg.coverage_count));
    const double T = 1.3;
    const hand::HandModel thick =
        resized(c.model, c.model.shape.dimensions.length, c.model.shape.dimensions.width, T).value();
    const ResidualProblem pt{&thick, &none, &image, nullptr, &c.params};
    VecX rt;
    stacked_residuals(pt, tg, c.q, &rt, nullptr);
    ASSERT_EQ(rt.size(), r.size());
    int palm = 0;
    for (int k = 0; k < tg.silhouette_count + tg.coverage_count; ++k) {
      const bool inward = k < tg.silhouette_count;
      const SilhouettePoint& sp = inward ? tg.silhouette[k] : tg.coverage[k - tg.silhouette_count];
      const double w = inward ? 1.0 / c.params.silhouette_sigma_px : sp.weight / c.params.coverage_sigma_px;
      const Vec2 expect = sp.bone >= 0 ? Vec2((T - 1) * w * sp.offset_px) : Vec2::Zero();
      palm += sp.bone < 0 ? 1 : 0;
      const Vec2 moved = rt.segment<2>(2 * k) - r.segment<2>(2 * k);
      EXPECT_NEAR(moved.x(), expect.x(), 1e-9) << "side " << side << " point " << k;
      EXPECT_NEAR(moved.y(), expect.y(), 1e-9) << "side " << side << " point " << k;
    }
    // The fingertips and joints did not move: the bones' axes are the same.
    EXPECT_GT(tg.silhouette_count + tg.coverage_count - palm, 5);
  }
}

TEST(ResidualJacobian, NonFiniteObservationsAreIgnored) {
  Case c;
  make_case(1, 7, &c);
  const ImageEvidence image = c.mask.evidence(&c.camera, false);
  const ResidualProblem pr{&c.model, &c.obs, &image, nullptr, &c.params};
  FrozenTargets tg;
  freeze_targets(pr, c.q, &tg);
  VecX r0, r1;
  stacked_residuals(pr, tg, c.q, &r0, nullptr);
  c.obs.p_W_fingertip[2].x() = std::numeric_limits<double>::quiet_NaN();
  c.obs.wrist_px = Vec2(std::numeric_limits<double>::infinity(), 3.0);
  freeze_targets(pr, c.q, &tg);
  stacked_residuals(pr, tg, c.q, &r1, nullptr);
  EXPECT_EQ(r1.size(), r0.size() - 3 - 2);
  EXPECT_TRUE(r1.allFinite());
}

TEST(SuccessiveAdjustment, NanStartAndObservationsGiveAFiniteFit) {
  Case c;
  make_case(0, 9, &c);
  const ImageEvidence image = c.mask.evidence(&c.camera, true);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.obs.p_W_fingertip[1] = Vec3(nan, 0, 0);
  c.obs.wrist_confidence = nan;
  c.prior[hand::kIndexDip] = nan;
  hand::HandParams q = c.q;
  q[hand::kMiddleDip] = nan;
  const FitReport rep = SuccessiveAdjustment(c.params).fit(c.model, c.obs, image, &c.prior, &q);
  EXPECT_TRUE(q.q.allFinite());
  EXPECT_TRUE(std::isfinite(rep.cost_final));
  EXPECT_TRUE(hand::within_limits(q, c.model.limits));
}

TEST(SuccessiveAdjustment, RejectsInvalidParams) {
  RegistrationParams p;
  p.joint_ball_sigma_px = -1;
  try {
    SuccessiveAdjustment s(p);
    FAIL() << "expected an exception";
  } catch (const SpidarError& e) {
    EXPECT_NE(std::string(e.what()).find("joint_ball_sigma_px"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace spidar::registration
