// The wrist's other depth (registration/wrist_depth.hpp): the pose turned about its fingertips so
// that its wrist lies at the other point of the band's ray at the same distance from them; a fit
// from there finds a hand left at the wrong depth again. The truth is drawn from the model's own
// capsules (no GL).
#include <gtest/gtest.h>

#include <cstdio>

#include "registration_test_util.hpp"
#include "spidar/registration/wrist_depth.hpp"

namespace spidar::registration {
namespace {

Vec3 fingertip_centroid(const hand::HandModel& model, const hand::HandParams& q) {
  const hand::HandPoints p = hand::forward_kinematics(model, q);
  Vec3 c = Vec3::Zero();
  for (int f = 0; f < hand::kFingertipCount; ++f) c += p.p_W_fingertip[f];
  return c / hand::kFingertipCount;
}

TEST(WristDepth, TheOtherPoseKeepsTheFingertipsAndTheWristPixelAndTurnsBack) {
  const vision::Camera camera = vision::default_rig_camera();
  for (int h = 0; h < 2; ++h) {
    const hand::HandModel model = test::model_hands()[h];
    const hand::HandParams q = test::reaching_hands()[h];
    HandObservation obs = test::exact_caps(model, q);
    obs.wrist_px = camera.project(q.p_W_wrist());
    const auto other = other_wrist_depth(model, q, obs, camera);
    ASSERT_TRUE(other.has_value()) << "hand " << h;
    const Vec3 c = fingertip_centroid(model, q);
    // On the same ray, at the same distance from the same fingertips, somewhere else.
    EXPECT_LT((camera.project(other->p_W_wrist()) - *obs.wrist_px).norm(), 1e-6) << "hand " << h;
    EXPECT_NEAR((other->p_W_wrist() - c).norm(), (q.p_W_wrist() - c).norm(), 1e-9);
    EXPECT_LT((fingertip_centroid(model, *other) - c).norm(), 1e-9);
    EXPECT_GT((other->p_W_wrist() - q.p_W_wrist()).norm(), 0.02);
    for (int k = hand::kThumbCmcFlexion; k < hand::kParamCount; ++k) EXPECT_EQ((*other)[k], q[k]);
    // The fingertips keep their shape: each is where the rigid turn puts it.
    const hand::HandPoints a = hand::forward_kinematics(model, q), b = hand::forward_kinematics(model, *other);
    for (int f = 0; f < hand::kFingertipCount; ++f)
      EXPECT_NEAR((b.p_W_fingertip[f] - c).norm(), (a.p_W_fingertip[f] - c).norm(), 1e-9);
    // The other depth's other depth is where it started.
    const auto back = other_wrist_depth(model, *other, obs, camera);
    ASSERT_TRUE(back.has_value());
    EXPECT_LT((back->p_W_wrist() - q.p_W_wrist()).norm(), 1e-6) << "hand " << h;
  }
}

TEST(WristDepth, NothingToTryWithoutAWristPixelOrThreeFingertipsOrWhereTheRayMissesTheSphere) {
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandModel model = test::model_hands()[1];
  const hand::HandParams q = test::reaching_hands()[1];
  HandObservation obs = test::exact_caps(model, q);
  EXPECT_FALSE(other_wrist_depth(model, q, obs, camera).has_value()) << "no wrist pixel";
  obs.wrist_px = camera.project(q.p_W_wrist());
  HandObservation two = obs;
  two.fingertip_valid[0] = two.fingertip_valid[1] = false;
  EXPECT_FALSE(other_wrist_depth(model, q, two, camera).has_value()) << "two fingertips";
  HandObservation far = obs;
  far.wrist_px = Vec2(0, 0);  // a ray far from the hand
  EXPECT_FALSE(other_wrist_depth(model, q, far, camera).has_value()) << "the ray misses the sphere";
  EXPECT_FALSE(other_wrist_depth(model, q, obs, camera, 10.0).has_value()) << "depths closer than asked";
}

// A hand fitted at the wrong depth agrees with the strings and the wrist pixel: a warm fit from it
// stays there. Fitted from the other depth, the same evidence brings it back to the truth, at a
// lower cost of the data terms (what FramePipeline compares).
TEST(WristDepth, AFitFromTheOtherDepthFindsAHandLeftAtTheWrongOne) {
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandModel model = test::model_hands()[1];
  const hand::HandParams truth = test::reaching_hands()[1];
  RegistrationParams params;
  params.silhouette_term = true;
  params.bracelet_offset_m = 0.0;  // the wrist term then pulls the wrist joint itself
  params.bracelet_surface_shift = 0.0;
  cv::Mat mask, alpha;
  test::draw_capsule_mask(model, truth, camera, &mask);
  mask.convertTo(alpha, CV_32FC1, 1.0 / 255.0);
  HandObservation obs = test::exact_caps(model, truth);
  obs.wrist_px = camera.project(truth.p_W_wrist());
  const auto wrong = other_wrist_depth(model, truth, obs, camera);
  ASSERT_TRUE(wrong.has_value());
  const double depth_error_m = (wrong->p_W_wrist() - truth.p_W_wrist()).norm();
  const SuccessiveAdjustment solver(params);
  std::array<std::vector<OwnedPixel>, 2> owned;
  ImageEvidence image;
  image.camera = &camera;
  image.alpha = alpha;
  image.coverage = &owned[1];
  auto fit = [&](hand::HandParams q, const hand::HandParams* prior, FitReport* report) {
    for (int round = 0; round < 3; ++round) {
      ProjectedHand outline;
      project_hand(model, q, camera, 0.03, &outline);
      coverage_evidence(mask, {nullptr, &outline}, params, &owned);
      *report = solver.fit(model, obs, image, prior, &q);
    }
    return q;
  };
  FitReport warm_report, other_report;
  const hand::HandParams warm = fit(*wrong, &*wrong, &warm_report);
  const auto start = other_wrist_depth(model, warm, obs, camera);
  ASSERT_TRUE(start.has_value());
  const hand::HandParams other = fit(*start, nullptr, &other_report);
  const double warm_m = (warm.p_W_wrist() - truth.p_W_wrist()).norm();
  const double other_m = (other.p_W_wrist() - truth.p_W_wrist()).norm();
  const double warm_data = warm_report.terms.total() - warm_report.terms.prior;
  const double other_data = other_report.terms.total() - other_report.terms.prior;
  std::printf("wrong depth %.0f mm off; warm fit %.1f mm off (data cost %.2f), from the other depth %.1f mm (%.2f)\n",
              1e3 * depth_error_m, 1e3 * warm_m, warm_data, 1e3 * other_m, other_data);
  EXPECT_GT(depth_error_m, 0.05);
  EXPECT_LT(other_m, 0.01) << "back at the true wrist";
  EXPECT_LT(other_data, warm_data) << "and the data say so";
}

}  // namespace
}  // namespace spidar::registration
