// The frame pipeline on synthetic frames: the simulated user's hands (their own proportions)
// filmed over the blue screen, registered with the default model hands, composited into a scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <cmath>
#include <cstdio>
#include <vector>

#include "source_path.hpp"
#include "spidar/device/servo_types.hpp"

#include <cstdlib>
#include <limits>
#include <opencv2/core.hpp>

#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/registration/shape_estimator.hpp"
#include "spidar/registration/wrist_depth.hpp"
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/sim/user_hands.hpp"
#include "spidar/vision/vision_config.hpp"

namespace spidar::pipeline {
namespace {

using spidar::test::source;

class FramePipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto ctx = render::Context::create_headless();
    if (!ctx) GTEST_SKIP() << "no headless OpenGL: " << ctx.error().message;
    context_ = std::move(ctx).value();
    const auto profiles = hand::load_hand_profiles(source("configs/hands.yaml"));
    const auto* user = profiles.find("user");
    truth_models_ = {user->model(hand::Side::kLeft), user->model(hand::Side::kRight)};
    models_ = {hand::default_hand_model(hand::Side::kLeft), hand::default_hand_model(hand::Side::kRight)};
    camera_ = vision::default_rig_camera();
    film_ = sim::SyntheticCamera::create(*context_, camera_, truth_models_).value();
    // The virtual cube where the user grasps.
    Shape cube;
    cube.type = Shape::Type::kBox;
    cube.size = Vec3(0.0285, 0.0285, 0.0285);
    cube.rgba = {0.9f, 0.9f, 0.9f, 1.f};
    cube.body = 1;
    scene_.shapes.push_back(cube);
  }

  // The user's hands at script time t with their caps on the goals; the fingertip sample as the
  // servo loop would publish it.
  device::FingertipSample pose_user(sim::UserHands& user, sim::RubiksTask& task, double t) {
    std::array<Vec3, 8> g;
    task.goals(t, g);
    user.update(t, g);
    device::FingertipSample s;
    s.finger_count = 8;
    for (int f = 0; f < 8; ++f) s.p_W[f] = {g[f].x(), g[f].y(), g[f].z()};
    return s;
  }

  // The shipped keyer and bracelet detector; the rest the library's defaults.
  static FramePipelineParams shipped_keyer_params() {
    const auto vc = vision::load_vision_config(source("configs/vision.yaml"));
    FramePipelineParams p;
    p.chroma_key = vc.chroma_key;
    p.bracelet = vc.bracelet;
    return p;
  }

  // The same, the fits starting from the hands' rotations in `task`'s script at `t` [s].
  static FramePipelineParams scripted_params(const sim::RubiksTask& task, double t) {
    FramePipelineParams p = shipped_keyer_params();
    for (int h = 0; h < 2; ++h)
      p.initial_r_W_hand[h] = task.nominal(t, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
    return p;
  }

  // The shipped keyer and bracelet detector, estimating the hands' sizes from keyframes of a short
  // stretch of the script.
  static FramePipelineParams personalising_params() {
    FramePipelineParams p = shipped_keyer_params();
    p.personalise_shape = true;
    p.shape_estimator.min_pose_change = 0.02;
    return p;
  }

  // SideBySideStagesGiveTheSerialResults, with or without the sizes estimated online.
  void side_by_side_matches_serial(bool personalise, bool shared);

  // The shipped keyer and bracelet detector, with the silhouette term.
  static FramePipelineParams keyed_params() {
    FramePipelineParams p = shipped_keyer_params();
    p.registration.silhouette_term = true;
    return p;
  }

  std::unique_ptr<render::Context> context_;
  std::array<hand::HandModel, 2> truth_models_, models_;
  vision::Camera camera_;
  std::unique_ptr<sim::SyntheticCamera> film_;
  SceneSnapshot scene_;
};

TEST_F(FramePipelineTest, TracksTheUsersHandsAndCompositesWithCorrectOcclusion) {
  sim::RubiksTask task({});
  const FramePipelineParams p = scripted_params(task, 1.5);
  auto pipe = FramePipeline::create(*context_, camera_, models_, p).value();
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  FrameResult r;
  sim::FrameTruthWorkspace ws;
  double tip_sum = 0, iou_sum = 0, occ = 0, occ_paper = 0, joint_sum = 0, floor_sum = 0;
  int n = 0, bracelets = 0;
  for (double t = 1.5; t < 3.5; t += 1.0 / 30) {
    const auto sample = pose_user(user, task, t);
    const auto& truth = user.params();
    ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
    ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r).ok());
    ASSERT_EQ(r.composite.size(), frame.bgr.size());
    ASSERT_FALSE(r.other.empty());
    const auto m = sim::measure_frame(frame, r, p.compositor.mode, models_, truth_models_, truth,
                                      camera_, &ws).value();
    if (t < 1.8) continue;  // let the cold start settle
    tip_sum += 0.5 * (m.fingertip_mm[0] + m.fingertip_mm[1]);
    iou_sum += m.iou;
    occ += m.occlusion_pct;
    occ_paper += m.occlusion_pct_paper;
    joint_sum += 0.5 * (m.joint_px[0] + m.joint_px[1]);
    floor_sum += 0.5 * (m.joint_px_floor[0] + m.joint_px_floor[1]);
    bracelets += (r.bracelets[0].found ? 1 : 0) + (r.bracelets[1].found ? 1 : 0);
    ++n;
  }
  ASSERT_GT(n, 40);
  // Measured (2026-11-24): fingertips 1.03 mm, IoU 0.874, occlusion 0.09 % vs 12.5 %, joints
  // 6.5 px above a floor of 2.0 px, bracelets 56 of 104: the two bands touch in these poses and
  // merge into one ambiguous piece, which is not assigned.
  EXPECT_LT(tip_sum / n, 3.0);   // the strings give the fingertips (noise-free here)
  EXPECT_GT(iou_sum / n, 0.65);  // another hand's proportions and skin over the model's
  EXPECT_LT(occ / n, 0.5 * occ_paper / n);  // the depth compositor beats the paper's cut-outs
  EXPECT_GE(bracelets, n / 2);   // a wrist term in most frames
  // The joint error's floor: the user's own little finger, which the model's (following the
  // ring finger's) cannot reach; the rest of the fit's error is above it.
  EXPECT_GT(floor_sum / n, 0.1);
  EXPECT_LT(floor_sum / n, joint_sum / n);
  std::printf("fingertips %.2f mm, IoU %.3f, occlusion %.2f %% (paper %.2f %%), bracelets %d/%d, joints %.2f px (floor %.2f)\n",
              tip_sum / n, iou_sum / n, occ / n, occ_paper / n, bracelets, 2 * n, joint_sum / n, floor_sum / n);

  // The wrists' depth error: the fitted hands replaced by the true ones moved 20 mm along the
  // camera's optical axis (left, away) and 20 mm across it (right), with the true sizes.
  const Vec3 axis_W = camera_.X_WC().R * Vec3::UnitZ();
  const Vec3 across_W = camera_.X_WC().R * Vec3::UnitX();
  const auto& truth = user.params();
  r.hands = truth;
  r.models = truth_models_;
  for (int k = 0; k < 3; ++k) {
    r.hands[0][hand::kWristX + k] += 0.020 * axis_W[k];
    r.hands[1][hand::kWristX + k] += 0.020 * across_W[k];
  }
  const auto moved = sim::measure_frame(frame, r, p.compositor.mode, truth_models_, truth_models_, truth,
                                        camera_, &ws).value();
  EXPECT_NEAR(moved.wrist_depth_mm[0], 20.0, 1e-6);
  EXPECT_NEAR(moved.wrist_depth_mm[1], 0.0, 1e-6);
}

// The report's keyframe: 2×2 without the ground truth (real hardware), and with the real hands'
// ids a third column whose top tile is the fit against the real hands (silhouette_loss_image).
TEST_F(FramePipelineTest, AKeyframeShowsTheFitAgainstTheRealHandsWhenTheTruthIsKnown) {
  sim::RubiksTask task({});
  const FramePipelineParams p = scripted_params(task, 2.0);
  auto pipe = FramePipeline::create(*context_, camera_, models_, p).value();
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  FrameResult r;
  const auto sample = pose_user(user, task, 2.0);
  const auto& truth = user.params();
  ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
  ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r).ok());
  const int w = frame.bgr.cols, h = frame.bgr.rows;
  const cv::Mat plain = sim::keyframe_montage(frame.bgr, r, p.compositor.mode, r.models, camera_, "caption");
  EXPECT_EQ(plain.cols, 2 * w);
  EXPECT_EQ(plain.rows, 2 * h + 28);
  const cv::Mat with = sim::keyframe_montage(frame.bgr, r, p.compositor.mode, r.models, camera_, "caption", &frame.hand_id);
  ASSERT_EQ(with.cols, 3 * w);
  EXPECT_EQ(with.rows, 2 * h + 28);
  cv::Mat loss;
  ASSERT_TRUE(sim::silhouette_loss_image(r.virt.hand_id, frame.hand_id, &loss).ok());
  ASSERT_GT(cv::countNonZero(loss.reshape(1)), 1000);  // the hands are in view
  // Below the tile's label, the tile is the loss picture.
  const cv::Rect below(0, 32, w, h - 32);
  cv::Mat diff;
  cv::absdiff(with(cv::Rect(2 * w, 0, w, h))(below), loss(below), diff);
  EXPECT_EQ(cv::countNonZero(diff.reshape(1)), 0);
  // A truth of another size is left out rather than drawn wrong.
  const cv::Mat small(h / 2, w / 2, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(sim::keyframe_montage(frame.bgr, r, p.compositor.mode, r.models, camera_, "caption", &small).cols, 2 * w);
}

// The hand-aware silhouette term (with the forearms' directions from their bands, the default)
// against the paper's joint-balls alone (its forearm in line), on the same frames of the simulated
// user's hands, their wrists bending as the demo's do: the approach (hands coming in from the
// sides, the worst frames of the paper's fit) through the grasp, the lift and the first turn.
TEST_F(FramePipelineTest, TheSilhouetteTermBeatsJointBallsOnTheSameFrames) {
  const auto vc = vision::load_vision_config(source("configs/vision.yaml"));
  sim::RubiksTask task({});
  task.fit_to_hands(truth_models_);
  sim::SyntheticCameraParams film_params;
  film_params.elbows_W = sim::user_elbows(task);
  auto film = sim::SyntheticCamera::create(*context_, camera_, truth_models_, film_params).value();
  std::array<std::unique_ptr<FramePipeline>, 2> pipes;  // 0: paper, 1: with the silhouette term
  FramePipelineParams p;
  p.chroma_key = vc.chroma_key;
  p.bracelet = vc.bracelet;
  const double t0 = 0.3;
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(t0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  for (int k = 0; k < 2; ++k) {
    p.registration.silhouette_term = k == 1;
    pipes[k] = FramePipeline::create(*context_, camera_, models_, p).value();
  }
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  FrameResult r;
  sim::FrameTruthWorkspace ws;
  std::array<double, 2> iou{}, joints{}, tips{}, worst{1.0, 1.0}, worst_t{};
  std::array<std::vector<double>, 2> per_frame;
  int n = 0;
  for (double t = t0; t < 6.0; t += 1.0 / 30) {
    const auto sample = pose_user(user, task, t);
    const auto& truth = user.params();
    ASSERT_TRUE(film->film({&truth[0], &truth[1]}, &frame).ok());
    for (int k = 0; k < 2; ++k) {
      ASSERT_TRUE(pipes[k]->process(frame.bgr, sample, scene_, &r).ok());
      const auto m = sim::measure_frame(frame, r, p.compositor.mode, models_, truth_models_, truth,
                                        camera_, &ws).value();
      iou[k] += m.iou;
      if (m.iou < worst[k]) worst[k] = m.iou, worst_t[k] = t;
      per_frame[k].push_back(m.iou);
      joints[k] += 0.5 * (m.joint_px[0] + m.joint_px[1]);
      tips[k] += 0.5 * (m.fingertip_mm[0] + m.fingertip_mm[1]);
    }
    ++n;
  }
  std::array<double, 2> p5{};
  for (int k = 0; k < 2; ++k) {
    std::sort(per_frame[k].begin(), per_frame[k].end());
    p5[k] = per_frame[k][static_cast<std::size_t>(0.05 * static_cast<double>(per_frame[k].size() - 1))];
    std::printf("%-22s IoU %.3f (p5 %.3f, worst %.3f at t = %.2f s), joints %.2f px, fingertips %.2f mm over %d frames\n",
                k ? "joint-balls+silhouette" : "joint-balls", iou[k] / n, p5[k], worst[k], worst_t[k], joints[k] / n,
                tips[k] / n, n);
  }
  // Measured (2026-11-25, frames 0.3–6.0 s: the approach, the grasp, the lift and the first turn;
  // the user's fingers reaching the caps through their passive ranges; both fits re-posing a digit
  // stalled short of its string, registration/fingertip_reach.hpp): IoU 0.834 → 0.847, joints
  // 6.49 → 6.28 px, fingertips 0.45 → 0.38 mm. The re-posed digits lifted the paper's hard frames
  // (p5 0.668 → 0.730, worst 0.657 → 0.685) and not the term's (p5 0.720 → 0.719, worst 0.644 at a
  // chaotic moment of contact, t = 1.37–1.43 s, where both fits glitch for a frame or two): the
  // term is behind through the fingers' closing (0.83–1.33 s), an open part of issue 14. What is
  // asserted: the term wins on the mean and the joints, and its hard frames do not collapse.
  // With the balls' σ at 8 px (2026-11-26, night) both fits gained, the paper's hard frames most:
  // IoU 0.838 → 0.863, p5 0.756 against 0.725, worst 0.682 against 0.706, joints 6.02 → 5.11 px.
  // (Over a whole demo run the term's p5 is ahead: 0.79–0.82 against 0.78–0.79, seeds 1–4.)
  // With the user's wrists bending and the forearms estimated from their bands (2026-11-28):
  // IoU 0.820 → 0.858, p5 0.685 → 0.763, worst 0.574 → 0.705, joints 5.89 → 5.23 px.
  EXPECT_GT(iou[1] / n, iou[0] / n + 0.01);
  EXPECT_GT(p5[1], p5[0] - 0.04);
  EXPECT_GT(worst[1], worst[0] - 0.06);  // one chaotic frame: a loose bound
  EXPECT_LT(joints[1] / n, joints[0] / n);
  EXPECT_LT(tips[1] / n, tips[0] / n + 0.2);
}

// A fit made with registration_only from another pipeline's matte, and pictured later by a third
// pipeline (on another context, as AsyncSinks does on its thread), is the fit and the picture
// process() makes in one go.
TEST_F(FramePipelineTest, PictureOfARegistrationOnlyFitIsTheFullProcessPicture) {
  const auto vc = vision::load_vision_config(source("configs/vision.yaml"));
  FramePipelineParams p;
  p.chroma_key = vc.chroma_key;
  p.bracelet = vc.bracelet;
  p.personalise_shape = true;  // the picture must use the sizes this frame's fit used
  sim::RubiksTask task({});
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(1.5, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  auto full = FramePipeline::create(*context_, camera_, models_, p).value();
  auto fit = FramePipeline::create(*context_, camera_, models_, p).value();
  auto other_context = render::Context::create_headless().value();
  auto painter = FramePipeline::create(*other_context, camera_, models_, p).value();
  // Without the other composite (the demo's frame thread), which is then made elsewhere.
  FramePipelineParams lean_params = p;
  lean_params.other_composite = false;
  auto lean = FramePipeline::create(*context_, camera_, models_, lean_params).value();
  render::Compositor other_compositor(other_compositor_params(p.compositor));
  EXPECT_NE(other_compositor.params().mode, p.compositor.mode);
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  FrameResult a, b, c;
  c.other = cv::Mat(2, 2, CV_8UC3);  // an older frame's, as in a result reused from a pool
  int frames = 0;
  for (double t = 1.5; t < 2.2; t += 1.0 / 30, ++frames) {
    const auto sample = pose_user(user, task, t);
    const auto& truth = user.params();
    ASSERT_TRUE(context_->make_current().ok());
    ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
    ASSERT_TRUE(full->process(frame.bgr, sample, scene_, &a).ok());
    // The fit keys nothing itself: it is given the full pipeline's matte of this image.
    ASSERT_TRUE(fit->process(frame.bgr, sample, scene_, &b, true, &a.key).ok());
    ASSERT_TRUE(other_context->make_current().ok());
    ASSERT_TRUE(painter->picture(frame.bgr, scene_, &b).ok());
    ASSERT_TRUE(context_->make_current().ok());
    ASSERT_TRUE(lean->process(frame.bgr, sample, scene_, &c).ok());
    EXPECT_TRUE(c.other.empty() && c.other_alpha.empty()) << t;
    EXPECT_EQ(cv::norm(a.composite, c.composite, cv::NORM_INF), 0.0) << t;
    cv::Mat other, other_alpha;
    ASSERT_TRUE(compose_result(other_compositor, c, frame.bgr, &other, &other_alpha).ok());
    EXPECT_EQ(cv::norm(a.other, other, cv::NORM_INF), 0.0) << t;
    EXPECT_EQ(cv::norm(a.other_alpha, other_alpha, cv::NORM_INF), 0.0) << t;
    for (int h = 0; h < 2; ++h) ASSERT_LT((a.hands[h].q - b.hands[h].q).norm(), 1e-12) << t;
    EXPECT_EQ(cv::norm(a.virt.hand_depth, b.virt.hand_depth, cv::NORM_INF), 0.0) << t;
    EXPECT_EQ(cv::norm(a.composite, b.composite, cv::NORM_INF), 0.0) << t;
    EXPECT_EQ(cv::norm(a.other_alpha, b.other_alpha, cv::NORM_INF), 0.0) << t;
  }
  // A matte of another size is refused.
  vision::ChromaKeyResult small;
  small.alpha = cv::Mat(4, 4, CV_32FC1, cv::Scalar(0));
  small.silhouette = cv::Mat(4, 4, CV_8UC1, cv::Scalar(0));
  ASSERT_TRUE(context_->make_current().ok());
  EXPECT_FALSE(fit->process(frame.bgr, device::FingertipSample{}, scene_, &b, true, &small).ok());
  ASSERT_TRUE(other_context->make_current().ok());
  // A result without its matte cannot be pictured.
  FrameResult empty;
  const auto st = painter->picture(frame.bgr, scene_, &empty);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("matte"), std::string::npos) << st.error().message;
  cv::Mat other;
  const auto composed = compose_result(other_compositor, empty, frame.bgr, &other, nullptr);
  ASSERT_FALSE(composed.ok());
  EXPECT_NE(composed.error().message.find("matte"), std::string::npos) << composed.error().message;
  ASSERT_TRUE(context_->make_current().ok());
}

// The matte and silhouette evidence on a helper thread beside the bracelets on the caller, and
// the left hand's fit beside the right's (FramePipelineParams::side_by_side), give exactly the
// serial pipeline's fits, sizes, mattes, bracelets and pictures, frame after frame (each stage
// and each hand writes only its own outputs; the fits' frames reach the size estimate after both
// fits), with the sizes fixed, estimated per hand, or one estimate for both hands.
TEST_F(FramePipelineTest, SideBySideStagesGiveTheSerialResults) {
  for (int personalise : {0, 1, 2}) {
    SCOPED_TRACE(personalise == 0 ? "fixed sizes" : personalise == 1 ? "sizes estimated per hand" : "one estimate for both");
    side_by_side_matches_serial(personalise > 0, personalise == 2);
  }
}

void FramePipelineTest::side_by_side_matches_serial(bool personalise, bool shared) {
  const auto vc = vision::load_vision_config(source("configs/vision.yaml"));
  FramePipelineParams p = personalise ? personalising_params() : FramePipelineParams{};
  p.chroma_key = vc.chroma_key;
  p.bracelet = vc.bracelet;
  p.registration.silhouette_term = true;  // the evidence stage on the helper does its whole work
  p.registration.silhouette_inward = true;
  p.shape_estimator.shared_hands = shared;
  sim::RubiksTask task({});
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(1.5, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  FramePipelineParams serial_params = p;
  p.side_by_side = true;
  serial_params.side_by_side = false;
  auto side = FramePipeline::create(*context_, camera_, models_, p).value();
  auto serial = FramePipeline::create(*context_, camera_, models_, serial_params).value();
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  FrameResult a, b;
  int found = 0, resized = 0;
  for (double t = 1.5; t < 2.3; t += 1.0 / 30) {
    const auto sample = pose_user(user, task, t);
    const auto& truth = user.params();
    ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
    ASSERT_TRUE(side->process(frame.bgr, sample, scene_, &a).ok()) << t;
    ASSERT_TRUE(serial->process(frame.bgr, sample, scene_, &b).ok()) << t;
    EXPECT_EQ(cv::norm(a.key.alpha, b.key.alpha, cv::NORM_INF), 0.0) << t;
    EXPECT_EQ(cv::norm(a.key.silhouette, b.key.silhouette, cv::NORM_INF), 0.0) << t;
    for (int h = 0; h < 2; ++h) {
      EXPECT_EQ(a.bracelets[h].found, b.bracelets[h].found) << t;
      if (a.bracelets[h].found && b.bracelets[h].found) {
        ++found;
        EXPECT_EQ((a.bracelets[h].wrist_px - b.bracelets[h].wrist_px).norm(), 0.0) << t;
      }
      ASSERT_EQ((a.hands[h].q - b.hands[h].q).norm(), 0.0) << "hand " << h << " at " << t;
      EXPECT_EQ(a.models[h].shape.dimensions.length, b.models[h].shape.dimensions.length) << t;
      EXPECT_EQ(a.models[h].shape.dimensions.width, b.models[h].shape.dimensions.width) << t;
      EXPECT_EQ(a.fits[h].iterations, b.fits[h].iterations) << t;
      if (a.models[h].shape.dimensions.width != models_[h].shape.dimensions.width) ++resized;
    }
    EXPECT_EQ(a.restarts, b.restarts) << t;
    EXPECT_EQ(a.depth_switches, b.depth_switches) << t;
    EXPECT_EQ(a.reaches, b.reaches) << t;
    EXPECT_EQ(cv::norm(a.composite, b.composite, cv::NORM_INF), 0.0) << t;
    EXPECT_GT(a.timings.key_ms, 0.0);
    EXPECT_GT(a.timings.bracelet_ms, 0.0);
  }
  EXPECT_GT(found, 20);  // the bracelets were seen: the stage on the caller did its work
  if (personalise) {
    EXPECT_GT(resized, 0);  // the estimators on both threads did their work
  }
}

// A fit that cannot agree with the strings is no evidence on the hand's sizes: with the right
// hand's caps three times as far apart as the hand has them (past any pose of the hand: at twice,
// fingers re-posed to their strings, registration/fingertip_reach.hpp, reach some of them within
// the gate's 2 σ), its frames are not offered to the size
// estimator (ShapeEstimatorParams::max_fingertip_cost), while the left hand's are; with the
// gate open, the broken fits become keyframes.
TEST_F(FramePipelineTest, BrokenFitsAreNoEvidenceOnTheHandsSizes) {
  FramePipelineParams p = personalising_params();
  p.shape_estimator.shared_hands = true;     // one estimate for both hands (checked below)
  // Fed by one hand only, an estimate of both re-estimates after 2 × solve_every of its keyframes:
  // half the count, for a re-estimate within this second.
  p.shape_estimator.solve_every = 5;
  sim::RubiksTask task({});
  task.fit_to_hands(truth_models_);
  const double t0 = 1.8;
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(t0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  std::array<std::array<int, 2>, 2> keyframes{};  // [gate closed, open][hand]
  for (int open = 0; open < 2; ++open) {
    FramePipelineParams q = p;
    if (open == 1) q.shape_estimator.max_fingertip_cost = 1e9;
    auto pipe = FramePipeline::create(*context_, camera_, models_, q).value();
    sim::UserHands user(truth_models_, task);
    sim::SyntheticFrame frame;
    FrameResult r;
    for (double t = t0; t < t0 + 1.0; t += 1.0 / 30) {
      auto sample = pose_user(user, task, t);
      const auto& truth = user.params();
      ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
      const auto p_W = device::fingertip_positions(sample);
      const Vec3 centre = 0.25 * (p_W[4] + p_W[5] + p_W[6] + p_W[7]);
      for (int f = 4; f < 8; ++f) {  // the right caps three times as far apart as the hand has them
        const Vec3 y = centre + 3.0 * (p_W[f] - centre);
        sample.p_W[f] = {y.x(), y.y(), y.z()};
      }
      ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r).ok());
    }
    for (int h = 0; h < 2; ++h) keyframes[open][h] = r.shapes[h].keyframes;
    if (open == 0) {
      // One estimate for both hands (ShapeEstimatorParams::shared_hands): the right hand offered
      // nothing, yet its model is at the sizes the left's keyframes gave.
      std::printf("gate closed: %d solves, left L %.4f W %.4f, right L %.4f W %.4f\n", r.shapes[1].solves,
                  r.shapes[0].length_m, r.shapes[0].width_m, r.shapes[1].length_m, r.shapes[1].width_m);
      EXPECT_GE(r.shapes[1].solves, 1);
      EXPECT_NE(r.shapes[1].length_m, models_[1].shape.dimensions.length);
      for (int h = 0; h < 2; ++h) {
        EXPECT_NEAR(pipe->models()[h].shape.dimensions.length, r.shapes[h].length_m, 1e-12) << h;
        EXPECT_NEAR(pipe->models()[h].shape.dimensions.width, r.shapes[h].width_m, 1e-12) << h;
      }
    }
  }
  std::printf("keyframes, left / right: gate %d / %d, open %d / %d\n", keyframes[0][0], keyframes[0][1],
              keyframes[1][0], keyframes[1][1]);
  EXPECT_GT(keyframes[0][0], 2);
  EXPECT_EQ(keyframes[0][1], 0);
  EXPECT_GT(keyframes[1][1], 2);  // the test can fail: the broken fits would be offered
}

// A frame of a moving hand mixes times (the camera's rows exposed one after another, the strings
// sampled at one instant), so the size estimator takes frames only while the hand is slower than
// ShapeEstimatorParams::max_keyframe_speed_m_s, its fingertips' speed taken from the strings'
// samples and their times. The script's hands grasp and lift the cube here: a gate at half the
// slowest frame's speed (its fastest fingertip's, measured by the test from the samples) lets no
// frame through; one at 100 m/s lets the frames through (all but the first, whose speed is not
// known; a speed read from wrong times, infinite or negative, would pass no gate).
TEST_F(FramePipelineTest, FastHandsAreNoEvidenceOnTheHandsSizes) {
  FramePipelineParams p = personalising_params();
  sim::RubiksTask task({});
  task.fit_to_hands(truth_models_);
  const double t0 = 1.8;
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(t0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  std::array<double, 3> gates{0.0, 0.0, 100.0};  // off, below the script's speed (set below), above it
  std::array<std::array<int, 2>, 3> keyframes{};
  double slowest = std::numeric_limits<double>::infinity();  // the slowest hand's fastest fingertip [m/s]
  for (std::size_t g = 0; g < gates.size(); ++g) {
    if (g == 1) {
      ASSERT_GT(slowest, 1e-4);  // the hands move in every frame of this stretch
      gates[1] = 0.5 * slowest;
    }
    FramePipelineParams q = p;
    q.shape_estimator.max_keyframe_speed_m_s = gates[g];
    auto pipe = FramePipeline::create(*context_, camera_, models_, q).value();
    sim::UserHands user(truth_models_, task);
    sim::SyntheticFrame frame;
    FrameResult r;
    std::optional<device::FingertipSample> before;
    for (double t = t0; t < t0 + 1.0; t += 1.0 / 30) {
      auto sample = pose_user(user, task, t);
      sample.t_ns = std::llround(t * 1e9);
      if (before && g == 0) {
        for (int h = 0; h < 2; ++h) {  // the device's fingers 0–3 are the left hand's, 4–7 the right's
          double fastest = 0;
          for (int f = 4 * h; f < 4 * h + 4; ++f)
            fastest = std::max(fastest, (device::fingertip_position(sample, f) - device::fingertip_position(*before, f)).norm() /
                                            (1e-9 * double(sample.t_ns - before->t_ns)));
          slowest = std::min(slowest, fastest);
        }
      }
      before = sample;
      const auto& truth = user.params();
      ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
      ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r).ok());
    }
    for (int h = 0; h < 2; ++h) keyframes[g][h] = r.shapes[h].keyframes;
  }
  std::printf("keyframes, left / right: no gate %d / %d, %.4f m/s %d / %d, 100 m/s %d / %d\n", keyframes[0][0],
              keyframes[0][1], gates[1], keyframes[1][0], keyframes[1][1], keyframes[2][0], keyframes[2][1]);
  for (int h = 0; h < 2; ++h) {
    EXPECT_GT(keyframes[0][h], 2) << h;
    EXPECT_EQ(keyframes[1][h], 0) << h;
    EXPECT_GT(keyframes[2][h], 2) << h;
  }
}

// The comparison fit takes the main fit's sizes (use_model_sizes) and keeps its own joint box.
TEST_F(FramePipelineTest, UseModelSizesTakesAnotherFitsSizesAndKeepsItsJointBox) {
  auto pipe = FramePipeline::create(*context_, camera_, models_, {}).value();
  std::array<hand::HandModel, 2> other = models_;
  other[1] = registration::resized(models_[1], 0.2, 0.09).value();
  other[1].limits = hand::ParamLimits{};  // another pipeline's box is not taken
  pipe->use_model_sizes(other);
  EXPECT_EQ(pipe->models()[1].shape.dimensions.length, 0.2);
  EXPECT_EQ(pipe->models()[1].shape.dimensions.width, 0.09);
  EXPECT_EQ(pipe->models()[1].side, hand::Side::kRight);
  EXPECT_EQ(pipe->models()[1].limits.lower, hand::passive_limits(models_[1].limits).lower);
  EXPECT_EQ(pipe->models()[1].limits.upper, hand::passive_limits(models_[1].limits).upper);
  EXPECT_EQ(pipe->models()[0].shape.dimensions.length, models_[0].shape.dimensions.length);
}

// A pipeline warm-started at the true pose fits the frame from there: the first frame is not a
// cold start, and with the user's own sizes it stays near the truth; a cold pipeline on the same
// frame starts from its nominal rotation. Non-finite poses are refused and change nothing.
TEST_F(FramePipelineTest, WarmStartFitsTheNextFrameFromTheGivenPoses) {
  const FramePipelineParams p = keyed_params();
  sim::RubiksTask task({});
  sim::UserHands user(truth_models_, task);
  const double t = 4.0;  // holding the cube, far from the script's start
  const auto sample = pose_user(user, task, t);
  const auto truth = user.params();
  sim::SyntheticFrame frame;
  ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());

  auto warm = FramePipeline::create(*context_, camera_, truth_models_, p).value();
  hand::HandParams broken = truth[0];
  broken.q[3] = std::numeric_limits<double>::quiet_NaN();
  const auto refused = warm->warm_start({broken, truth[1]});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("left"), std::string::npos) << refused.error().message;
  EXPECT_FALSE(warm->has_previous());

  ASSERT_TRUE(warm->warm_start(truth).ok());
  EXPECT_TRUE(warm->has_previous());
  FrameResult r;
  ASSERT_TRUE(warm->process(frame.bgr, sample, scene_, &r).ok());
  for (int h = 0; h < 2; ++h) {
    EXPECT_LT((r.hands[h].p_W_wrist() - truth[h].p_W_wrist()).norm(), 0.005) << "hand " << h;
    EXPECT_LT(r.fits[h].iterations, 40) << "hand " << h << ": a warm fit, not first_frame_rounds";
  }
  // Without it the same frame is a cold start (first_frame_rounds from the nominal rotation).
  auto cold = FramePipeline::create(*context_, camera_, truth_models_, p).value();
  FrameResult c;
  ASSERT_TRUE(cold->process(frame.bgr, sample, scene_, &c).ok());
  EXPECT_GT(c.fits[0].iterations + c.fits[1].iterations, r.fits[0].iterations + r.fits[1].iterations)
      << "cold " << c.fits[0].iterations << "+" << c.fits[1].iterations << ", warm " << r.fits[0].iterations << "+"
      << r.fits[1].iterations;
}

// The wrist's other depth along the band's ray (FramePipelineParams::other_depth_every) is taken
// only at its second win in a row (other_depth_confirm). Both pipelines are warm-started with the
// right hand at the wrong depth (registration::other_wrist_depth of the truth) and fit the same
// frame again and again: every try from the other (true) depth wins. With one win enough, the
// first try switches; with two, the try after it (other_depth_every frames later), and not the
// first. Either way the wrist ends at the true depth.
TEST_F(FramePipelineTest, TheWristsOtherDepthIsTakenAtItsSecondWinInARow) {
  sim::RubiksTask task({});
  sim::UserHands user(truth_models_, task);
  const double t = 7.8;  // turn 2 begins: the right forearm points along the camera's ray
  const auto sample = pose_user(user, task, t);
  const auto truth = user.params();
  sim::SyntheticFrame frame;
  ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
  registration::HandObservation obs;  // what other_wrist_depth uses: the caps and the wrist pixel
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    obs.p_W_fingertip[f] = device::fingertip_position(sample, 4 + f);
    obs.fingertip_valid[f] = true;
  }
  obs.wrist_px = camera_.project(truth[1].p_W_wrist());
  const auto wrong = registration::other_wrist_depth(truth_models_[1], truth[1], obs, camera_);
  ASSERT_TRUE(wrong.has_value());
  ASSERT_GT((wrong->p_W_wrist() - truth[1].p_W_wrist()).norm(), 0.05) << "no wrong depth to start from";

  std::array<int, 2> first_switch{-1, -1};  // frame index of the right hand's first switch
  std::array<double, 2> end_m{};            // the right wrist's distance from the truth at the end
  for (int confirm = 0; confirm < 2; ++confirm) {
    FramePipelineParams p = keyed_params();
    p.other_depth_confirm = confirm == 1;
    auto pipe = FramePipeline::create(*context_, camera_, truth_models_, p).value();
    ASSERT_TRUE(pipe->warm_start({truth[0], *wrong}).ok());
    FrameResult r;
    for (int k = 0; k < 4 * p.other_depth_every; ++k) {
      ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r).ok());
      const bool right_far = (r.hands[1].p_W_wrist() - truth[1].p_W_wrist()).norm() > 0.03;
      if (k == 0) {
        ASSERT_TRUE(right_far) << "the warm fit left the wrong depth by itself: nothing to switch";
      }
      if (first_switch[confirm] < 0 && !right_far) first_switch[confirm] = k;
    }
    end_m[confirm] = (r.hands[1].p_W_wrist() - truth[1].p_W_wrist()).norm();
  }
  std::printf("first switch at frame %d (one win) and %d (two wins in a row); wrist at the end %.1f / %.1f mm "
              "from the truth\n",
              first_switch[0], first_switch[1], 1e3 * end_m[0], 1e3 * end_m[1]);
  const int every = FramePipelineParams{}.other_depth_every;
  ASSERT_GE(first_switch[0], 0) << "no switch with one win";
  EXPECT_LT(first_switch[0], every);
  EXPECT_EQ(first_switch[1], first_switch[0] + every);
  EXPECT_LT(end_m[0], 0.01);
  EXPECT_LT(end_m[1], 0.01);
}

// Forearm directions given to the pipeline (a rig that tracks the forearms, the study's oracle):
// the in-line direction is the default bit for bit, a bent one moves the fits, and a broken one
// is the in-line forearm.
TEST_F(FramePipelineTest, GivenForearmDirectionsMoveTheBraceletAndInLineIsTheDefault) {
  FramePipelineParams p = keyed_params();
  p.registration.forearm_from_band = false;  // the in-line forearm when none is given
  sim::RubiksTask task({});
  sim::UserHands user(truth_models_, task);
  const double t = 4.0;
  const auto sample = pose_user(user, task, t);
  const auto truth = user.params();
  sim::SyntheticFrame frame;
  ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
  auto fit_with = [&](const std::array<std::optional<Vec3>, 2>& directions) {
    auto pipe = FramePipeline::create(*context_, camera_, truth_models_, p).value();
    EXPECT_TRUE(pipe->warm_start(truth).ok());
    pipe->set_forearm_directions(directions);
    FrameResult r;
    EXPECT_TRUE(pipe->process(frame.bgr, sample, scene_, &r, true).ok());
    return r;
  };
  const FrameResult plain = fit_with({});
  std::array<std::optional<Vec3>, 2> in_line, bent, broken;
  for (int h = 0; h < 2; ++h) {
    const Mat3 R = hand::hand_pose(truth[h]).R.toRotationMatrix();
    in_line[h] = -R.col(1);
    bent[h] = (-R.col(1) + 0.9 * R.col(2)).normalized();  // bent 42° toward the hand's back
    broken[h] = Vec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
  }
  const FrameResult a = fit_with(in_line), b = fit_with(bent), c = fit_with(broken);
  for (int h = 0; h < 2; ++h) {
    ASSERT_TRUE(plain.bracelets[h].found) << "hand " << h;
    EXPECT_LT((a.hands[h].q - plain.hands[h].q).norm(), 1e-9) << "hand " << h;
    EXPECT_EQ((c.hands[h].q - plain.hands[h].q).norm(), 0.0) << "hand " << h;
    EXPECT_TRUE(b.hands[h].q.allFinite());
    // The bent forearm's band sits 12 mm · sin 42° ≈ 8 mm elsewhere: the wrist moves to put it
    // on the detected band.
    EXPECT_GT((b.hands[h].p_W_wrist() - plain.hands[h].p_W_wrist()).norm(), 1e-3) << "hand " << h;
  }
}

// A user whose wrists bend (forearms toward elbows that stay put, sim::user_elbows): where the
// band is seen from the side (a strip, thinner than half its length), the forearm directions
// estimated from it (RegistrationParams::forearm_from_band) are nearer the simulated forearms than
// the paper's in-line forearm, over the turn of the script. (Nearer end-on, the two signs of the
// tilt look alike, and the estimate can take the wrong one: docs/measurements.md.)
TEST_F(FramePipelineTest, ABandSeenFromTheSideShowsWhereABentForearmPoints) {
  sim::RubiksTask task({});
  task.fit_to_hands(truth_models_);
  sim::SyntheticCameraParams film_params;
  film_params.elbows_W = sim::user_elbows(task);
  auto film = sim::SyntheticCamera::create(*context_, camera_, truth_models_, film_params).value();
  // [°] per frame and hand where both runs saw the band from the side: estimated, in line.
  std::array<std::map<std::pair<int, int>, double>, 2> err;
  for (const bool estimate : {true, false}) {
    FramePipelineParams p = keyed_params();
    p.registration.forearm_from_band = estimate;
    const double t0 = 3.5;
    for (int h = 0; h < 2; ++h)
      p.initial_r_W_hand[h] = task.nominal(t0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
    auto pipe = FramePipeline::create(*context_, camera_, truth_models_, p).value();
    sim::UserHands user(truth_models_, task);
    sim::SyntheticFrame frame;
    FrameResult r;
    const int k = estimate ? 0 : 1;
    int i = 0;
    for (double t = t0; t < t0 + 1.5; t += 1.0 / 30, ++i) {
      const auto sample = pose_user(user, task, t);
      const auto& truth = user.params();
      ASSERT_TRUE(film->film({&truth[0], &truth[1]}, &frame).ok());
      ASSERT_TRUE(pipe->process(frame.bgr, sample, scene_, &r, true).ok()) << t;
      for (int h = 0; h < 2; ++h) ASSERT_TRUE(r.toward_elbow_W[h].allFinite());
      if (t < t0 + 0.3) continue;  // the first frames start in line
      for (int h = 0; h < 2; ++h) {
        const auto& b = r.bracelets[h];
        if (!b.found || !(b.thickness_px < 0.5 * b.length_px)) continue;
        const Vec3& d = *frame.toward_elbow_W[static_cast<std::size_t>(h)];
        err[k][{i, h}] = std::acos(std::clamp(d.normalized().dot(r.toward_elbow_W[h]), -1.0, 1.0)) * 180.0 / 3.14159265;
      }
    }
  }
  std::vector<double> estimated, in_line;
  for (const auto& [key, e] : err[0]) {
    const auto it = err[1].find(key);
    if (it == err[1].end()) continue;
    estimated.push_back(e);
    in_line.push_back(it->second);
  }
  ASSERT_GT(estimated.size(), 10u);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf("forearm direction error, median over %zu hand-frames: estimated %.1f°, in line %.1f°\n",
              estimated.size(), median(estimated), median(in_line));
  EXPECT_GT(median(in_line), 15.0);  // the user's wrists do bend here
  EXPECT_LT(median(estimated), 0.6 * median(in_line));
}

TEST_F(FramePipelineTest, BadFramesAreErrorsNamingTheSize) {
  auto pipe = FramePipeline::create(*context_, camera_, models_, {}).value();
  FrameResult r;
  device::FingertipSample s;
  const auto e = pipe->process(cv::Mat(10, 10, CV_8UC3), s, scene_, &r);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().message.find("640x480"), std::string::npos) << e.error().message;
  EXPECT_FALSE(pipe->process(cv::Mat(480, 640, CV_8UC1), s, scene_, &r).ok());
  FramePipelineParams bad;
  bad.fingers[1][2] = 9;
  const auto c = FramePipeline::create(*context_, camera_, models_, bad);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("finger index 9"), std::string::npos);
}

}  // namespace
}  // namespace spidar::pipeline

#include "spidar/registration/metrics.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/hand_skin.hpp"

namespace spidar::pipeline {
namespace {

// How much of the IoU a perfect pose can reach: the user's hands at their true pose, with their
// own sizes, drawn as the model's capsules and as the model's skin (render/hand_skin.hpp with
// FramePipelineParams::model_skin) against the filmed hands. Prints both over the script (run with
// --gtest_also_run_disabled_tests).
TEST_F(FramePipelineTest, DISABLED_PrintIouCeilingOfTheModelShapes) {
  auto renderer = render::Renderer::create(*context_, camera_.width(), camera_.height()).value();
  const render::HandSkinParams skin = FramePipelineParams{}.model_skin;
  auto meshes = std::make_shared<std::vector<MeshData>>();
  std::array<render::HandSkin, 2> skins;
  for (int h = 0; h < 2; ++h) skins[h] = render::build_hand_skin(truth_models_[h], skin, meshes.get());
  sim::RubiksTask task({});
  sim::UserHands user(truth_models_, task);
  sim::SyntheticFrame frame;
  render::RenderTargets t;
  double sum_caps = 0, sum_skin = 0;
  int n = 0;
  auto iou_of = [&](const SceneSnapshot& hands) {
    EXPECT_TRUE(renderer->render(hands, camera_).ok());
    EXPECT_TRUE(renderer->read(&t, render::kHandId).ok());
    cv::Mat mask(t.hand_id.size(), CV_8UC1);
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x) {
        const auto id = t.hand_id.at<std::uint8_t>(y, x);
        const int f = render::decode_hand_id(id).finger;
        mask.at<std::uint8_t>(y, x) = id != 0 && f != render::kForearmPart && f != render::kBraceletPart ? 255 : 0;
      }
    return registration::mask_iou(mask, frame.hand_only);
  };
  for (double time = 0.0; time < 12.0; time += 0.25) {
    pose_user(user, task, time);
    const auto& truth = user.params();
    ASSERT_TRUE(film_->film({&truth[0], &truth[1]}, &frame).ok());
    SceneSnapshot capsules, skinned;
    skinned.meshes = meshes;
    for (int h = 0; h < 2; ++h) {
      render::append_hand_shapes(hand::hand_render_shapes(truth_models_[h], truth[h]), &capsules);
      render::pose_hand_skin(truth_models_[h], skins[h], truth[h], skin, &skinned);
    }
    const double a = iou_of(capsules), b = iou_of(skinned);
    sum_caps += a;
    sum_skin += b;
    ++n;
    std::printf("t %5.2f  IoU at the true pose: capsules %.3f, skin %.3f\n", time, a, b);
  }
  std::printf("mean over %d poses: capsules %.3f, skin %.3f\n", n, sum_caps / n, sum_skin / n);
}

}  // namespace
}  // namespace spidar::pipeline

namespace spidar::pipeline {
namespace {

TEST(CopyFrameResult, CopiesEveryImageDeeplyAndReusesTheTargetsBuffers) {
  FrameResult a;
  int k = 1;
  std::vector<cv::Mat*> images = {&a.key.alpha, &a.key.silhouette, &a.key.foreground, &a.virt.colour,
                                  &a.virt.depth, &a.virt.hand_depth, &a.virt.hand_id, &a.composite,
                                  &a.composite_alpha, &a.other, &a.other_alpha};
  for (cv::Mat* m : images) *m = cv::Mat(3, 4, CV_8UC1, cv::Scalar(k++));
  a.hands[1].q[4] = 0.25;
  a.restarts = 2;
  a.timings.render_ms = 7.5;
  FrameResult b;
  copy_frame_result(a, &b);
  const std::vector<cv::Mat*> copies = {&b.key.alpha, &b.key.silhouette, &b.key.foreground, &b.virt.colour,
                                        &b.virt.depth, &b.virt.hand_depth, &b.virt.hand_id, &b.composite,
                                        &b.composite_alpha, &b.other, &b.other_alpha};
  std::vector<const std::uint8_t*> buffers;
  for (std::size_t i = 0; i < images.size(); ++i) {
    ASSERT_EQ(copies[i]->size(), images[i]->size()) << i;
    EXPECT_NE(copies[i]->data, images[i]->data) << i;  // not a shared header
    EXPECT_EQ(copies[i]->at<std::uint8_t>(2, 3), static_cast<int>(i) + 1) << i;
    buffers.push_back(copies[i]->data);
  }
  EXPECT_DOUBLE_EQ(b.hands[1].q[4], 0.25);
  EXPECT_EQ(b.restarts, 2);
  EXPECT_DOUBLE_EQ(b.timings.render_ms, 7.5);
  // Overwriting the source leaves the copy; copying again reuses the copy's buffers.
  for (cv::Mat* m : images) m->setTo(99);
  for (std::size_t i = 0; i < copies.size(); ++i) EXPECT_EQ(copies[i]->at<std::uint8_t>(0, 0), static_cast<int>(i) + 1);
  copy_frame_result(a, &b);
  for (std::size_t i = 0; i < copies.size(); ++i) {
    EXPECT_EQ(copies[i]->data, buffers[i]) << i;
    EXPECT_EQ(copies[i]->at<std::uint8_t>(0, 0), 99) << i;
  }
  // An empty image empties the copy (e.g. no second composite).
  a.other.release();
  copy_frame_result(a, &b);
  EXPECT_TRUE(b.other.empty());
}

}  // namespace
}  // namespace spidar::pipeline
