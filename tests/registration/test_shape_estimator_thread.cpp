// The size estimator's re-estimate on a thread of its own (ShapeEstimatorParams::apply_after_frames):
// the same sizes as the inline re-estimate, bit for bit, taking effect only when polled. This
// executable links the registration module alone, so the ThreadSanitizer build (make test-tsan)
// runs it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

/// Frame k of a hand of `truth`'s sizes opening and closing its fingers: the pose, and its caps
/// as the strings measure them (exactly).
std::pair<hand::HandParams, HandObservation> frame(const hand::HandModel& truth, int k) {
  hand::HandParams q;
  q.set_wrist(Vec3(0.0, 0.0, 0.25), Vec3(0.3, 0.0, 0.0));
  for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) q[i] = 0.4 + 0.35 * std::sin(0.05 * k + 0.7 * i);
  q = hand::clamp_to_limits(q, truth.limits);
  const hand::HandPoints pts = hand::forward_kinematics(truth, q);
  HandObservation obs;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    obs.p_W_fingertip[f] = pts.p_W_fingertip[f];
    obs.fingertip_valid[f] = true;
  }
  return {q, obs};
}

TEST(ShapeEstimatorThread, EqualsTheInlineReEstimateAndTakesEffectWhenPolled) {
  const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), 0.205, 0.088).value();
  const hand::HandModel start = hand::default_hand_model(hand::Side::kRight);
  const ImageEvidence no_image;
  const RegistrationParams rp;
  ShapeEstimatorParams async_p;
  async_p.apply_after_frames = 3;
  ShapeEstimator inline_est(start, {}), async_est(start, async_p);
  int frames = 0, solves = 0;
  for (int k = 0; k < 300 && solves < 2; ++k, ++frames) {
    const auto [q, obs] = frame(truth, k);
    const bool inline_changed = inline_est.add_frame(q, obs, no_image, rp);
    EXPECT_FALSE(async_est.add_frame(q, obs, no_image, rp));  // never applied inside add_frame
    if (!inline_changed) continue;
    ++solves;
    ASSERT_TRUE(async_est.solving());
    const double before = async_est.model().shape.dimensions.length;
    EXPECT_FALSE(async_est.poll());
    EXPECT_FALSE(async_est.poll());
    EXPECT_EQ(async_est.model().shape.dimensions.length, before);  // not yet
    EXPECT_TRUE(async_est.poll());                                 // the third poll applies it
    EXPECT_FALSE(async_est.solving());
    EXPECT_EQ(async_est.estimate().length_m, inline_est.estimate().length_m);
    EXPECT_EQ(async_est.estimate().width_m, inline_est.estimate().width_m);
    EXPECT_EQ(async_est.estimate().sigma_length_m, inline_est.estimate().sigma_length_m);
    EXPECT_EQ(async_est.estimate().solves, inline_est.estimate().solves);
    EXPECT_EQ(async_est.model().shape.dimensions.width, inline_est.model().shape.dimensions.width);
  }
  EXPECT_EQ(solves, 2) << "after " << frames << " frames";
  std::printf("after %d frames: L %.4f W %.4f (truth 0.205 / 0.088), both ways\n", frames,
              async_est.estimate().length_m, async_est.estimate().width_m);
}

TEST(ShapeEstimatorThread, AnEstimatorDestroyedWhileSolvingWaitsForItsThread) {
  const hand::HandModel truth = resized(hand::default_hand_model(hand::Side::kRight), 0.205, 0.088).value();
  ShapeEstimatorParams p;
  p.apply_after_frames = 1000;
  ShapeEstimator busy(hand::default_hand_model(hand::Side::kRight), p);
  for (int k = 0; k < 300 && !busy.solving(); ++k) {
    const auto [q, obs] = frame(truth, k);
    busy.add_frame(q, obs, ImageEvidence{}, RegistrationParams{});
  }
  EXPECT_TRUE(busy.solving());
  ShapeEstimator moved = std::move(busy);  // the thread's result goes with the move
  EXPECT_TRUE(moved.solving());
}

}  // namespace
}  // namespace spidar::registration
