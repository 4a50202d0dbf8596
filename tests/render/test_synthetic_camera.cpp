// The synthetic camera: its own chroma-key round trip, ground truth consistency, bracelets,
// motion blur.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "gl_test_support.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/chroma_key.hpp"
#include "spidar/vision/lens_undistortion.hpp"
#include "synthetic_hands.hpp"

namespace spidar::sim {
namespace {

using render::test::gl_context;

double iou(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat i, u;
  cv::bitwise_and(a, b, i);
  cv::bitwise_or(a, b, u);
  return static_cast<double>(cv::countNonZero(i)) / std::max(1, cv::countNonZero(u));
}

TEST(SyntheticCamera, ChromaKeyRecoversTheGroundTruthMask) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  auto camera = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models()).value();
  const auto q = render::test::reaching_hands();
  SyntheticFrame frame;
  ASSERT_TRUE(camera->film({&q[0], &q[1]}, &frame).ok());
  ASSERT_EQ(frame.bgr.type(), CV_8UC3);
  ASSERT_EQ(frame.bgr.size(), cv::Size(640, 480));
  const int area = cv::countNonZero(frame.mask);
  EXPECT_GT(area, 20000);
  vision::ChromaKeyResult key;
  ASSERT_TRUE(vision::chroma_key(frame.bgr, vision::ChromaKeyParams{}, &key).ok());
  const double score = iou(key.silhouette, frame.mask);
  std::cout << "chroma-key IoU vs ground truth: " << score << " over " << area << " px\n";
  EXPECT_GE(score, 0.98);

  // Ground truth agrees with itself: depth exactly where the mask is; both hands present.
  cv::Mat finite = frame.depth < std::numeric_limits<float>::infinity();
  EXPECT_EQ(cv::countNonZero(finite != frame.mask), 0);
  EXPECT_GT(cv::countNonZero(frame.hand_index == 1), 5000);
  EXPECT_GT(cv::countNonZero(frame.hand_index == 2), 5000);
  // The part ids say the same: some palm and some digit of each hand, and hand_only is their palms
  // and digits.
  ASSERT_EQ(frame.hand_id.size(), frame.mask.size());
  std::array<std::array<int, 2>, 2> palm_digit{};
  for (int y = 0; y < frame.hand_id.rows; ++y)
    for (int x = 0; x < frame.hand_id.cols; ++x) {
      const std::uint8_t id = frame.hand_id.at<std::uint8_t>(y, x);
      ASSERT_EQ(id != 0, frame.mask.at<std::uint8_t>(y, x) != 0) << x << "," << y;
      const render::HandId d = render::decode_hand_id(id);
      const bool own = id != 0 && d.finger != render::kForearmPart && d.finger != render::kBraceletPart;
      ASSERT_EQ(own, frame.hand_only.at<std::uint8_t>(y, x) != 0) << x << "," << y;
      if (own) ++palm_digit[static_cast<std::size_t>(d.hand)][d.finger == render::kPalmPart ? 0 : 1];
    }
  for (const auto& h : palm_digit) {
    EXPECT_GT(h[0], 1000);
    EXPECT_GT(h[1], 1000);
  }
}

// A camera with a webcam's barrel lens films through it: its raw frame's key misses the ground
// truth where the lens bends the image, and the frame undistorted into the lens's pinhole camera
// (vision::LensUndistortion, as a session does) lies on it again.
TEST(SyntheticCamera, AFrameFilmedThroughALensUndistortsOntoItsGroundTruth) {
  SPIDAR_REQUIRE_GL();
  vision::Camera cam = vision::default_rig_camera();
  vision::Intrinsics k = cam.intrinsics();
  k.distortion = {-0.28, 0.09, 0.0008, -0.0005, 0.0};
  cam.set_intrinsics(k);
  const auto lens = vision::LensUndistortion::create(k);
  ASSERT_TRUE(lens) << lens.error().message;
  auto camera = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models()).value();
  const auto q = render::test::reaching_hands();
  SyntheticFrame frame;
  ASSERT_TRUE(camera->film({&q[0], &q[1]}, &frame).ok());
  vision::ChromaKeyResult raw, undistorted;
  ASSERT_TRUE(vision::chroma_key(frame.bgr, vision::ChromaKeyParams{}, &raw).ok());
  cv::Mat image;
  lens->undistort(frame.bgr, &image);
  ASSERT_TRUE(vision::chroma_key(image, vision::ChromaKeyParams{}, &undistorted).ok());
  const double before = iou(raw.silhouette, frame.mask), after = iou(undistorted.silhouette, frame.mask);
  std::cout << "chroma-key IoU vs the pinhole ground truth: raw frame " << before << ", undistorted " << after << "\n";
  EXPECT_LT(before, 0.95);  // the lens matters here: the test could fail
  EXPECT_GE(after, 0.97);
  // The same hands filmed through a pinhole camera of the lens's pinhole intrinsics give the same
  // ground truth.
  auto pinhole = SyntheticCamera::create(*gl_context(), vision::Camera(lens->pinhole(), cam.X_CW()),
                                         render::test::truth_models())
                     .value();
  SyntheticFrame plain;
  ASSERT_TRUE(pinhole->film({&q[0], &q[1]}, &plain).ok());
  EXPECT_GE(iou(plain.mask, frame.mask), 0.999);
}

TEST(SyntheticCamera, BraceletsSitAtTheWrists) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  const auto models = render::test::truth_models();
  auto camera = SyntheticCamera::create(*gl_context(), cam, models).value();
  const auto q = render::test::reaching_hands();
  SyntheticFrame frame;
  ASSERT_TRUE(camera->film({&q[0], &q[1]}, &frame).ok());
  vision::BraceletWorkspace ws;
  auto wrists = vision::detect_bracelets(frame.bgr, vision::BraceletParams{}, nullptr, &ws);
  ASSERT_TRUE(wrists.ok()) << wrists.error().message;
  for (int h = 0; h < 2; ++h) {
    ASSERT_TRUE((*wrists)[h].found) << "hand " << h;
    const Vec2 expected = cam.project(q[h].p_W_wrist() - 0.012 * hand::hand_pose(q[h]).R.toRotationMatrix().col(1));
    // The camera sees the upper half of the ring, whose middle lies toward the camera from the
    // ring's axis: allow about the ring's projected radius.
    EXPECT_LT(((*wrists)[h].wrist_px - expected).norm(), 15.0) << "hand " << h;
  }
}

// With elbows (a bending wrist), the bracelet sits on the forearm pointing at the elbow, not on
// the hand's axis, and the frame says where each forearm pointed; without, the frame says nothing.
TEST(SyntheticCamera, WithElbowsTheBraceletFollowsTheForearm) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  const auto models = render::test::truth_models();
  const auto q = render::test::reaching_hands();
  vision::BraceletWorkspace ws;
  auto detect = [&](SyntheticCamera& c, SyntheticFrame* frame) {
    EXPECT_TRUE(c.film({&q[0], &q[1]}, frame).ok());
    auto wrists = vision::detect_bracelets(frame->bgr, vision::BraceletParams{}, nullptr, &ws);
    EXPECT_TRUE(wrists.ok());
    return wrists.value();
  };
  auto straight_camera = SyntheticCamera::create(*gl_context(), cam, models).value();
  SyntheticFrame frame;
  const auto straight = detect(*straight_camera, &frame);
  EXPECT_FALSE(frame.toward_elbow_W[0].has_value() || frame.toward_elbow_W[1].has_value());

  // Elbows 0.8 rad (46 deg) off the hands' axes, sideways (about z_H: the image plane, roughly).
  SyntheticCameraParams p;
  std::array<Vec3, 2> toward;
  p.elbows_W.emplace();
  for (int h = 0; h < 2; ++h) {
    const Mat3 R = hand::hand_pose(q[h]).R.toRotationMatrix();
    toward[h] = Eigen::AngleAxisd(0.8, R.col(2)) * Vec3(-R.col(1));
    (*p.elbows_W)[h] = q[h].p_W_wrist() + 0.26 * toward[h];
  }
  auto bent_camera = SyntheticCamera::create(*gl_context(), cam, models, p).value();
  const auto bent = detect(*bent_camera, &frame);
  for (int h = 0; h < 2; ++h) {
    ASSERT_TRUE(frame.toward_elbow_W[h].has_value());
    EXPECT_LT((*frame.toward_elbow_W[h] - toward[h]).norm(), 1e-9);
    ASSERT_TRUE(straight[h].found && bent[h].found) << "hand " << h;
    // The detected band moves the way the band's centre does when the forearm swings onto the
    // elbow (not by as much: the detector takes the middle of the band's visible extent, which
    // turns with the band and which the palm now partly hides).
    const Mat3 R = hand::hand_pose(q[h]).R.toRotationMatrix();
    const Vec2 moved = cam.project(q[h].p_W_wrist() + p.bracelet_offset_m * toward[h]) -
                       cam.project(q[h].p_W_wrist() - p.bracelet_offset_m * R.col(1));
    ASSERT_GT(moved.norm(), 4.0) << "hand " << h << ": the bend must show in the image";
    const Vec2 seen = bent[h].wrist_px - straight[h].wrist_px;
    std::cout << "hand " << h << ": band moved " << seen.transpose() << " px, its centre "
              << moved.transpose() << " px\n";
    EXPECT_GT(seen.norm(), 4.0) << "hand " << h;
    EXPECT_GT(seen.dot(moved), 0.3 * seen.norm() * moved.norm()) << "hand " << h;
  }
}

TEST(SyntheticCamera, DiffersFromTheModelsCapsules) {
  SPIDAR_REQUIRE_GL();
  // The "real" hands are not the registration's geometry: same pose, visibly different masks.
  const vision::Camera cam = vision::default_rig_camera();
  const auto q = render::test::reaching_hands();
  SyntheticCameraParams p;
  p.forearm_length_m = 0;
  auto camera = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models(), p).value();
  SyntheticFrame frame;
  ASSERT_TRUE(camera->film({&q[0], &q[1]}, &frame).ok());
  SceneSnapshot scene;
  const auto models = render::test::truth_models();
  for (int h = 0; h < 2; ++h)
    render::append_hand_shapes(hand::hand_render_shapes(models[h], q[h]), &scene);
  auto renderer = render::Renderer::create(*gl_context()).value();
  ASSERT_TRUE(renderer->render(scene, cam).ok());
  render::RenderTargets t;
  ASSERT_TRUE(renderer->read(&t, render::kHandId).ok());
  const double score = iou(t.hand_id > 0, frame.mask);
  EXPECT_GT(score, 0.6);
  EXPECT_LT(score, 0.97);
}

TEST(SyntheticCamera, FilmsAnAnatomicalHandNotTheModelsSkin) {
  SPIDAR_REQUIRE_GL();
  // The simulated world is not the model (docs/architecture.md, sim): the filmed hand is the user's anatomical
  // hand, not the skin the registration draws. Same pose, same sizes: the hands (no forearm, no
  // bracelet) overlap mostly but clearly differ (the model's skin at the true pose scored 0.993
  // when the camera filmed it).
  const vision::Camera cam = vision::default_rig_camera();
  const auto q = render::test::reaching_hands();
  const auto models = render::test::truth_models();
  auto camera = SyntheticCamera::create(*gl_context(), cam, models).value();
  SyntheticFrame frame;
  ASSERT_TRUE(camera->film({&q[0], &q[1]}, &frame).ok());

  render::HandSkinParams model_skin{.taper = 0.12, .palm_fullness = 1.2, .forearm_length_m = 0.10, .bracelet = false};  // the pipeline's model skin
  auto meshes = std::make_shared<std::vector<MeshData>>();
  std::array<render::HandSkin, 2> skins;
  for (int h = 0; h < 2; ++h) skins[h] = render::build_hand_skin(models[h], model_skin, meshes.get());
  SceneSnapshot scene;
  scene.meshes = meshes;
  for (int h = 0; h < 2; ++h) render::pose_hand_skin(models[h], skins[h], q[h], model_skin, &scene);
  auto renderer = render::Renderer::create(*gl_context()).value();
  ASSERT_TRUE(renderer->render(scene, cam).ok());
  render::RenderTargets t;
  ASSERT_TRUE(renderer->read(&t, render::kHandId).ok());
  cv::Mat model_hand(t.hand_id.size(), CV_8UC1);
  for (int y = 0; y < model_hand.rows; ++y)
    for (int x = 0; x < model_hand.cols; ++x) {
      const std::uint8_t id = t.hand_id.at<std::uint8_t>(y, x);
      model_hand.at<std::uint8_t>(y, x) =
          id != 0 && render::decode_hand_id(id).finger != render::kForearmPart ? 255 : 0;
    }
  const double score = iou(model_hand, frame.hand_only);
  std::cout << "IoU anatomical hand vs model skin (hands only, same pose and sizes): " << score
            << " (" << cv::countNonZero(frame.hand_only) << " vs " << cv::countNonZero(model_hand)
            << " px)\n";
  EXPECT_GT(score, 0.75);
  EXPECT_LT(score, 0.97);

  // The forearm and bracelet are in the mask but not in hand_only.
  EXPECT_GT(cv::countNonZero(frame.mask) - cv::countNonZero(frame.hand_only), 2000);

  // To look at them: SPIDAR_TEST_IMAGES=dir writes the frame, both masks and close-ups.
  if (const char* dir = std::getenv("SPIDAR_TEST_IMAGES")) {
    const std::string d(dir);
    cv::imwrite(d + "/anatomical_frame.png", frame.bgr);
    cv::Mat both(model_hand.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    both.setTo(cv::Scalar(0, 0, 255), model_hand);
    both.setTo(cv::Scalar(0, 255, 0), frame.hand_only);
    both.setTo(cv::Scalar(255, 255, 255), model_hand & frame.hand_only);
    cv::imwrite(d + "/anatomical_vs_model.png", both);
    vision::Intrinsics K = cam.intrinsics();
    const Vec3 c = q[1].p_W_wrist() + 0.08 * hand::hand_pose(q[1]).R.toRotationMatrix().col(1);
    int k = 0;
    for (const Vec3& eye : {Vec3(0.0, 0.0, 0.32), Vec3(0.0, 0.0, -0.32), Vec3(0.25, -0.15, 0.05)}) {
      ASSERT_TRUE(camera->set_camera(vision::Camera(K, vision::look_at(c + eye, c, Vec3::UnitY()))).ok());
      SyntheticFrame close;
      ASSERT_TRUE(camera->film({&q[0], &q[1]}, &close).ok());
      cv::imwrite(d + "/anatomical_close" + std::to_string(k++) + ".png", close.bgr);
    }
  }
}

TEST(SyntheticCamera, MotionBlurAndNoiseLeaveGroundTruthAtTheCurrentPose) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  SyntheticCameraParams p;
  p.motion_blur_samples = 4;
  auto camera = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models(), p).value();
  const auto now = render::test::reaching_hands(), before = render::test::reaching_hands(-0.02);
  SyntheticFrame sharp, blurred;
  ASSERT_TRUE(camera->film({&now[0], &now[1]}, &sharp).ok());
  const HandPoses prev = {&before[0], &before[1]};
  ASSERT_TRUE(camera->film({&now[0], &now[1]}, &blurred, &prev).ok());
  EXPECT_EQ(cv::countNonZero(sharp.mask != blurred.mask), 0);
  cv::Mat diff;
  cv::absdiff(sharp.bgr, blurred.bgr, diff);
  cv::Mat big = diff > 40;
  EXPECT_GT(cv::countNonZero(big.reshape(1)), 1000);  // smeared edges, not just noise
  // Noise is there, and reproducible from the seed.
  auto again = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models(), p).value();
  SyntheticFrame first;
  ASSERT_TRUE(again->film({&now[0], &now[1]}, &first).ok());
  EXPECT_EQ(cv::norm(first.bgr, sharp.bgr, cv::NORM_INF), 0.0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(sharp.bgr(cv::Rect(0, 0, 40, 40)), mean, stddev);  // a patch of blue screen
  EXPECT_GT(stddev[0], 1.0);
  EXPECT_LT(stddev[0], 3.5);
  // Against the same frame without noise: zero-mean with σ = noise_sigma, both signs (over the
  // whole frame; saturation at 0 and 255 hardly occurs with σ = 2).
  SyntheticCameraParams quiet = p;
  quiet.noise_sigma = 0;
  auto clean_camera = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models(), quiet).value();
  SyntheticFrame clean;
  ASSERT_TRUE(clean_camera->film({&now[0], &now[1]}, &clean).ok());
  cv::Mat a16, b16, noise;
  sharp.bgr.convertTo(a16, CV_16SC3);
  clean.bgr.convertTo(b16, CV_16SC3);
  cv::subtract(a16, b16, noise);
  cv::meanStdDev(noise.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 0.05);
  EXPECT_NEAR(stddev[0], p.noise_sigma, 0.1);
  EXPECT_GT(cv::countNonZero(noise.reshape(1) > 0), noise.total());      // of 3 × total samples
  EXPECT_GT(cv::countNonZero(noise.reshape(1) < 0), noise.total());
}

// film_image hands over the image alone and film_truth reads that film's ground truth after it
// (sim::CameraThread publishes in between): together they give what film gives, and a
// film_truth without its film_image is an error, not a stale or empty truth.
TEST(SyntheticCamera, TheImageAndItsGroundTruthCanBeFilmedApart) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  auto whole = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models()).value();
  auto apart = SyntheticCamera::create(*gl_context(), cam, render::test::truth_models()).value();
  const auto q = render::test::reaching_hands(), other = render::test::reaching_hands(-0.03);
  SyntheticFrame a, b;
  EXPECT_FALSE(apart->film_truth(&b).ok());  // nothing filmed yet
  ASSERT_TRUE(whole->film({&q[0], &q[1]}, &a).ok());
  ASSERT_TRUE(apart->film_image({&q[0], &q[1]}, &b).ok());
  EXPECT_TRUE(b.mask.empty());  // the image only
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0);  // the same seed: the same noise
  ASSERT_TRUE(apart->film_truth(&b).ok());
  for (auto [x, y] : {std::pair{&a.mask, &b.mask}, {&a.hand_index, &b.hand_index}, {&a.hand_only, &b.hand_only},
                        {&a.hand_id, &b.hand_id}}) {
    ASSERT_EQ(x->size(), y->size());
    EXPECT_EQ(cv::countNonZero(*x != *y), 0);
  }
  EXPECT_GT(cv::countNonZero(b.mask), 20000);
  cv::Mat same_depth = (a.depth == b.depth) | (a.depth != a.depth);
  EXPECT_EQ(cv::countNonZero(same_depth == 0), 0);
  EXPECT_FALSE(apart->film_truth(&b).ok());  // read once per film_image
  // The truth read after another film_image is that film's, not the first one's.
  SyntheticFrame c;
  ASSERT_TRUE(apart->film_image({&other[0], &other[1]}, &c).ok());
  ASSERT_TRUE(apart->film_truth(&c).ok());
  EXPECT_GT(cv::countNonZero(c.mask != b.mask), 500);
}

TEST(SyntheticCamera, RejectsBadParams) {
  SyntheticCameraParams p;
  p.motion_blur_samples = 0;
  EXPECT_FALSE(validate(p).ok());
  p = {};
  p.noise_sigma = -1;
  EXPECT_NE(validate(p).error().message.find("noise_sigma"), std::string::npos);
  p = {};
  p.max_wrist_bend_rad = 2.0;
  EXPECT_NE(validate(p).error().message.find("max_wrist_bend_rad"), std::string::npos);
  p = {};
  p.elbows_W = std::array<Vec3, 2>{Vec3(NAN, 0, 0), Vec3::Zero()};
  EXPECT_NE(validate(p).error().message.find("elbows_W"), std::string::npos);
}

}  // namespace
}  // namespace spidar::sim
