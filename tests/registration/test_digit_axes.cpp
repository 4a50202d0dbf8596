// The digits' axes (RegistrationParams::digit_axis_sigma_px): across each phalanx the silhouette's
// two edges, and the axis pulled onto their midpoint. Checked on mattes drawn from a hand of the
// same skeleton with thicker or thinner digits than the model's: the midpoint is the real axis
// whatever the thickness.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "registration_test_util.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

struct Frozen {
  FrozenTargets tg;
  int near = 0;      ///< axis targets within 0.75 px of the true axis
  double worst = 0;  ///< the farthest target from the true axis [px]
};

/// Freezes the targets of the model (default right hand) at pose `q` on a matte drawn from the
/// hand `real` at `truth`, and measures each axis target's distance from the true projected axis.
Frozen freeze_on(const hand::HandModel& real, const hand::HandParams& truth, const hand::HandParams& q,
                 double axis_sigma_px) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const vision::Camera camera = vision::default_rig_camera();
  cv::Mat mask;
  test::draw_capsule_mask(real, truth, camera, &mask);
  test::MaskEvidence ev;
  test::evidence_from_mask(mask, &ev);
  const ImageEvidence image = ev.evidence(&camera, false);
  RegistrationParams params;
  params.silhouette_term = true;
  params.digit_axis_sigma_px = axis_sigma_px;
  const HandObservation obs;  // no strings, no bracelet: the image terms alone
  const ResidualProblem pr{&model, &obs, &image, nullptr, &params};
  Frozen out;
  freeze_targets(pr, q, &out.tg);
  const hand::HandPoints truth_pts = hand::forward_kinematics(real, truth);
  for (int k = 0; k < out.tg.axis_count; ++k) {
    const DigitAxisPoint& ap = out.tg.axes[k];
    const BoneRef b = silhouette_bone(ap.bone);
    // The true bone's ends: the skeleton is the model's, so the same joints.
    const int j0 = hand::joint_index(b.finger, b.segment - (b.finger == hand::kThumb ? 0 : 1));
    const Vec2 a = camera.project(truth_pts.p_W_joint[j0]);
    const Vec2 c = camera.project(truth_pts.p_W_joint[j0 + 1]);
    const Vec2 n = Vec2(-(c - a).y(), (c - a).x()).normalized();
    const double off = std::abs(n.dot(ap.target_px - a));  // from the true axis line
    out.near += off < 0.75 ? 1 : 0;
    out.worst = std::max(out.worst, off);
  }
  return out;
}

/// A right hand facing the camera with its fingers spread and a little bent: its phalanges are seen
/// apart from each other and from the palm.
hand::HandParams spread_hand() {
  hand::HandParams q = test::reaching_hands(0)[1];
  for (int f : {hand::kIndexMcpFlexion, hand::kMiddleMcpFlexion, hand::kRingMcpFlexion}) q[f] = 0.15;
  for (int f : {hand::kIndexDip, hand::kMiddleDip, hand::kRingDip}) q[f] = 0.2;
  q[hand::kIndexMcpAbduction] = 0.25;
  q[hand::kRingMcpAbduction] = 0.25;
  return q;
}

TEST(DigitAxes, FindTheRealAxisOfThickerAndThinnerDigits) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams truth = spread_hand();
  for (double thickness : {0.8, 1.0, 1.3}) {
    const hand::HandModel real =
        resized(model, model.shape.dimensions.length, model.shape.dimensions.width, thickness).value();
    const Frozen f = freeze_on(real, truth, truth, 5.0);
    std::printf("thickness %.1f: %d axis targets, %d within 0.75 px of the true axis, worst %.2f px\n", thickness,
                f.tg.axis_count, f.near, f.worst);
    EXPECT_GE(f.tg.axis_count, 8) << thickness;  // thicker digits touch: fewer sections stand alone
    // The phalanges' cross-sections away from the palm and each other: nearly all on the axis
    // (a digit drawn over another's end, or the palm's box, moves an edge).
    EXPECT_GE(f.near, f.tg.axis_count - 2) << thickness;
  }
}

TEST(DigitAxes, PullADisplacedModelBackAndLeaveFarOnesAlone) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams truth = spread_hand();
  const hand::HandModel thick =
      resized(model, model.shape.dimensions.length, model.shape.dimensions.width, 1.3).value();
  // The model's digits a little off the real ones: the targets still lie on the real axes.
  hand::HandParams q = truth;
  q[hand::kIndexMcpAbduction] += 0.04;
  q[hand::kMiddleMcpFlexion] += 0.05;
  q[hand::kRingMcpAbduction] -= 0.04;
  const Frozen near = freeze_on(thick, truth, q, 5.0);
  std::printf("displaced: %d targets, %d on the true axis, worst %.2f px\n", near.tg.axis_count, near.near, near.worst);
  EXPECT_GE(near.tg.axis_count, 8);
  EXPECT_GE(near.near, near.tg.axis_count - 2);
  // Their rows pull toward the truth: the cost of the axis rows is lower at the truth.
  // (Costs of the joint-ball term, which the axes' rows count with, with the balls off.)
  const vision::Camera camera = vision::default_rig_camera();
  RegistrationParams params;
  params.silhouette_term = true;
  params.joint_ball_alpha = 0.0;  // balls without a pull: only the axes' rows remain in the term
  params.digit_axis_sigma_px = 5.0;
  cv::Mat mask;
  test::draw_capsule_mask(thick, truth, camera, &mask);
  test::MaskEvidence ev;
  test::evidence_from_mask(mask, &ev);
  const ImageEvidence image = ev.evidence(&camera, false);
  const HandObservation obs;
  const ResidualProblem pr{&model, &obs, &image, nullptr, &params};
  FrozenTargets tg;
  freeze_targets(pr, q, &tg);
  const double at_q = term_costs(pr, tg, q).joint_ball, at_truth = term_costs(pr, tg, truth).joint_ball;
  EXPECT_GT(at_q, 1.0);
  EXPECT_LT(at_truth, 0.2 * at_q);
  // A model a whole palm's breadth off finds no digit within its radius: no target at all
  // (a neighbouring finger is not this one).
  hand::HandParams far = truth;
  far.set_wrist(truth.p_W_wrist() + Vec3(0.04, 0.0, 0.0), truth.r_W_hand());
  const Frozen off = freeze_on(thick, truth, far, 5.0);
  EXPECT_LE(off.tg.axis_count, 2);
  // Off (σ 0) or without the silhouette term (the paper's method), nothing is frozen.
  EXPECT_EQ(freeze_on(thick, truth, q, 0.0).tg.axis_count, 0);
}

}  // namespace
}  // namespace spidar::registration

namespace spidar::registration {
namespace {

// The digits' sections (digit_sections) at the true pose, on a matte drawn at sub-pixel precision
// from the hand's own capsules: the widths against the model's outline in perspective. Measured:
// nearly straight fingers read 0–6 % wide (not understood: the walk's sub-pixel crossing was
// checked and is not it), and a section a third of the way along a bent phalanx may cross the next
// bone's rounded end and read up to 13 % wide: the size estimate's radius ends a few per cent
// wide (test_shape_estimator). Hands ±10 % as broad as the model; fingers nearly straight, then as
// in the reaching pose.
TEST(DigitSections, ReadEachDigitAsThickAsItsCapsule) {
  const vision::Camera camera = vision::default_rig_camera();
  for (const double W : {0.085, 0.0935, 0.0765}) {
    const hand::HandModel m = resized(hand::default_hand_model(hand::Side::kRight), 0.19, W).value();
    for (const double bend : {0.2, 1.0}) {
      hand::HandParams q = test::reaching_hands(0)[1];
      for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) q[i] *= bend;
      cv::Mat mask;
      test::draw_capsule_mask(m, q, camera, &mask, true, true);
      const auto sections = digit_sections(m, q, camera, mask, 0.5);
      int single = 0;
      for (const auto& s : sections) {
        const double ratio = s.width_px / s.model_width_px;
        if (ratio > 1.35) continue;  // two fingers side by side (the size estimate leaves them out)
        ++single;
        EXPECT_GT(ratio, 0.96) << W << " bend " << bend << " bone " << s.bone;
        EXPECT_LT(ratio, bend < 0.5 ? 1.08 : 1.15) << W << " bend " << bend << " bone " << s.bone;
      }
      if (bend < 0.5) {
        EXPECT_GT(single, 4) << W;  // the reaching pose shows few digits across
      }
    }
  }
  // No matte, a matte of another type or a pose that is not finite: no sections.
  const hand::HandModel m = hand::default_hand_model(hand::Side::kRight);
  hand::HandParams q = test::reaching_hands(0)[1];
  EXPECT_TRUE(digit_sections(m, q, camera, cv::Mat(), 0.5).empty());
  EXPECT_TRUE(digit_sections(m, q, camera, cv::Mat(480, 640, CV_16UC1, cv::Scalar(1)), 0.5).empty());
  q[hand::kThumbCmcFlexion] = std::nan("");
  cv::Mat full(480, 640, CV_8UC1, cv::Scalar(255));
  EXPECT_TRUE(digit_sections(m, q, camera, full, 0.5).empty());
}

// A section whose edge lies inside another part of the hand's outline (section_clearance_px < 0)
// may read that part's edge, and an edge on another part's own boundary (the far side of a
// neighbour the digit merges with in the matte) lies within a pixel or so of it. Hands drawn from
// their own capsules with the index and ring fingers turned toward the middle one (past their
// limits, as a finger seen partly behind its neighbour is), read at the true pose: every section
// that reads more than 8 % wide has an edge less than 2 px clear of another part, and every
// section whose edges are 2 px clear reads its capsule within 8 % (nearly straight
// digits read 0-6 % wide: DigitSections.ReadEachDigitAsThickAsItsCapsule). The size estimate keeps
// only the clear ones (ShapeEstimatorParams::digit_section_clear_edges).
TEST(DigitSections, OnlyThoseWithAnEdgeInsideAnotherPartReadWide) {
  const vision::Camera camera = vision::default_rig_camera();
  int wide = 0, clear = 0;
  for (const double W : {0.085, 0.0935, 0.0765}) {
    const hand::HandModel m = resized(hand::default_hand_model(hand::Side::kRight), 0.19, W).value();
    for (const double toward : {0.0, 0.15, 0.25, 0.35}) {
      hand::HandParams q = test::reaching_hands(0)[1];
      for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) q[i] *= 0.2;
      for (const double sign : {1.0, -1.0}) {
        hand::HandParams crossed = q;
        crossed[hand::kIndexMcpAbduction] += sign * toward;
        crossed[hand::kRingMcpAbduction] -= sign * toward;
        cv::Mat mask;
        test::draw_capsule_mask(m, crossed, camera, &mask, true, true);
        ProjectedHand outline;
        project_hand(m, crossed, camera, 0.0, &outline);
        for (const auto& s : digit_sections(m, crossed, camera, mask, 0.5)) {
          const double ratio = s.width_px / s.model_width_px;
          if (ratio > 1.35) continue;  // two fingers side by side (the size estimate leaves them out)
          const double c = section_clearance_px(outline, s);
          if (ratio > 1.08) {
            ++wide;
            EXPECT_LT(c, 2.0) << W << " toward " << sign * toward << " bone " << s.bone << " ratio " << ratio;
          }
          if (c >= 2.0) {
            ++clear;
            EXPECT_GT(ratio, 0.96) << W << " toward " << sign * toward << " bone " << s.bone;
            EXPECT_LT(ratio, 1.08) << W << " toward " << sign * toward << " bone " << s.bone;
          }
        }
      }
    }
  }
  std::printf("sections read wide: %d; with clear edges: %d\n", wide, clear);
  EXPECT_GT(wide, 5);    // the crossed fingers do read some digits wide
  EXPECT_GT(clear, 20);  // and the others stay measurable
}

// section_clearance_px: two capsules side by side, a section across one of them. Its edge is
// clear of the other by the gap between them, and inside it once they overlap; a lone capsule is
// clear everywhere (+∞).
TEST(DigitSections, ClearanceIsTheEdgesDistanceFromTheOtherParts) {
  ProjectedHand hand;
  ImageCapsule& a = hand.bones[5];
  ImageCapsule& b = hand.bones[8];
  a = {Vec2(100, 100), Vec2(100, 200), 10, 10, true};
  DigitAxisPoint s;
  s.bone = 5;
  s.target_px = Vec2(100, 150);
  s.across_px = Vec2(1, 0);
  s.width_px = 20;  // edges at x = 90 and 110
  EXPECT_TRUE(std::isinf(section_clearance_px(hand, s)));
  for (const double x : {135.0, 125.0, 118.0}) {
    b = {Vec2(x, 100), Vec2(x, 200), 10, 10, true};
    EXPECT_NEAR(section_clearance_px(hand, s), x - 10 - 110, 1e-9) << x;
  }
  b.valid = false;  // a part not drawn is no neighbour
  EXPECT_TRUE(std::isinf(section_clearance_px(hand, s)));
}

}  // namespace
}  // namespace spidar::registration
