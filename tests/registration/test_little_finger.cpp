// A little finger of its own (RegistrationParams::little_free): the image moves it where the
// paper's model can only copy the ring finger, and the paper's method never frees it. The truth
// is drawn from the model's own capsules (no GL), so the little finger is all that differs.
#include <gtest/gtest.h>

#include <cstdio>

#include "registration_test_util.hpp"
#include "spidar/registration/metrics.hpp"

namespace spidar::registration {
namespace {

/// Mean projected distance [px] of the little finger's PIP, DIP and tip from the truth's.
double little_joints_px(const hand::HandModel& model, const hand::HandParams& q, const hand::HandParams& truth,
                 const vision::Camera& camera) {
  const hand::HandPoints a = hand::forward_kinematics(model, q), b = hand::forward_kinematics(model, truth);
  double sum = 0;
  for (int k = 1; k < 4; ++k) {
    const int j = hand::joint_index(hand::kLittle, k);
    sum += (camera.project(a.p_W_joint[j]) - camera.project(b.p_W_joint[j])).norm();
  }
  return sum / 3;
}

struct LittleFit {
  double little_px = 0;  ///< the little finger's joints from the truth's [px]
  double others_px = 0;  ///< every other joint [px]
  hand::HandParams q;
};

// The right hand's silhouette drawn (no GL) at a truth whose little finger is curled and spread
// away from the ring finger's angles; four exact fingertips; the fit starts at the truth's pose
// with the little finger copying the ring, as the paper's model would have it, and follows the
// image over a few frames (the owners recomputed at each, as in the tracker).
LittleFit fit_little(const RegistrationParams& params, const Vec3& little_offset, int frames = 6) {
  const hand::HandModel model = test::model_hands()[1];
  hand::HandParams truth = test::reaching_hands()[1];
  truth.little_independent = true;
  truth.set_little(truth.ring() + little_offset);
  const vision::Camera camera = vision::default_rig_camera();
  cv::Mat mask;
  test::draw_capsule_mask(model, truth, camera, &mask);
  const HandObservation obs = test::exact_caps(model, truth);
  hand::HandParams q = truth;
  q.little_independent = false;
  q.set_little(Vec3::Zero());
  const SuccessiveAdjustment solver(params);
  std::array<std::vector<OwnedPixel>, 2> owned;
  ImageEvidence image;
  image.camera = &camera;
  image.coverage = &owned[1];
  cv::Mat alpha;
  mask.convertTo(alpha, CV_32FC1, 1.0 / 255.0);
  image.alpha = alpha;
  for (int frame = 0; frame < frames; ++frame) {
    ProjectedHand outline;
    project_hand(model, q, camera, 0.03, &outline);
    coverage_evidence(mask, {nullptr, &outline}, params, &owned);
    const hand::HandParams prior = q;
    const FitReport r = solver.fit(model, obs, image, &prior, &q);
    EXPECT_TRUE(q.q.allFinite()) << "frame " << frame;
    EXPECT_TRUE(std::isfinite(r.cost_final));
  }
  LittleFit out;
  out.q = q;
  out.little_px = little_joints_px(model, q, truth, camera);
  const hand::HandPoints a = hand::forward_kinematics(model, q), b = hand::forward_kinematics(model, truth);
  int n = 0;
  for (int j = 0; j < hand::joint_index(hand::kLittle, 0); ++j, ++n)
    out.others_px += (camera.project(a.p_W_joint[j]) - camera.project(b.p_W_joint[j])).norm();
  out.others_px /= n;
  return out;
}

TEST(LittleFinger, AFreeLittleFingerFollowsTheImageAndFreesTheOtherJoints) {
  for (const Vec3& offset : {Vec3(0.35, 0.1, 0.25), Vec3(-0.25, 0.12, 0.0), Vec3(0.2, -0.15, 0.3)}) {
    RegistrationParams coupled;
    coupled.silhouette_term = true;
    coupled.little_free = false;
    // At the paper's ball weight. At the shipped σ (8 px) this capsule-drawn hand's curled little
    // finger is too weakly held to leave the ring's angles in 6 frames (or in 20: 21.0 → 20.2,
    // 16.5 → 5.5, 15.9 → 17.9 px); in the demo, at 8 px, the free little finger still lowers the
    // joint error (default user, seeds 1–3: 6.14 → 5.95 px; docs/measurements.md, "The
    // joint-balls' σ").
    coupled.joint_ball_sigma_px = 4.0;
    RegistrationParams free = coupled;
    free.little_free = true;
    const LittleFit a = fit_little(coupled, offset);
    const LittleFit b = fit_little(free, offset);
    std::printf("little offset (%.2f, %.2f, %.2f) rad: little %.2f px copied, %.2f px free; others %.2f / %.2f px\n",
                offset.x(), offset.y(), offset.z(), a.little_px, b.little_px, a.others_px, b.others_px);
    EXPECT_FALSE(a.q.little_independent);
    EXPECT_TRUE(b.q.little_independent);
    // Measured: the little finger 21.1 → 18.0, 20.1 → 12.8, 15.7 → 13.1 px, and the other joints
    // 5.9 → 3.2, 3.4 → 1.9, 5.0 → 4.2 px: the copied little finger's pixels no longer pull the ring
    // finger and the wrist. A curled little finger behind the palm stays poorly observed.
    EXPECT_LT(b.little_px, a.little_px - 1.0) << offset.transpose();
    EXPECT_LT(b.others_px, a.others_px - 0.4) << offset.transpose();
  }
}

TEST(LittleFinger, ThePapersMethodAndNoImageKeepTheLittleFingerCopyingTheRing) {
  // little_free without the silhouette term is the paper's method: the little finger copies the
  // ring, whatever the start said.
  RegistrationParams paper;
  paper.little_free = true;
  EXPECT_FALSE(little_moves_freely(paper));
  const LittleFit a = fit_little(paper, Vec3(0.35, 0.1, 0.25));
  EXPECT_FALSE(a.q.little_independent);

  // With no image at all a free little finger has only its coupling prior: it stays at the ring's
  // angles it started from.
  const hand::HandModel model = test::model_hands()[1];
  const hand::HandParams truth = test::reaching_hands()[1];
  RegistrationParams free;
  free.silhouette_term = true;
  free.little_free = true;
  hand::HandParams q = truth;
  const SuccessiveAdjustment solver(free);
  solver.fit(model, test::exact_caps(model, truth), ImageEvidence{}, nullptr, &q);
  EXPECT_TRUE(q.little_independent);
  EXPECT_LT((q.little() - q.ring()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_TRUE(hand::within_limits(q, model.limits, 1e-12));
}

}  // namespace
}  // namespace spidar::registration
