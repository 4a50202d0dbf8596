// The compositor on constructed inputs: a vertical "finger" over an object, in front of it or
// behind, with the real matte offset from the virtual hand by a few pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "spidar/render/compositor.hpp"

namespace spidar::render {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const cv::Vec3b kObject(90, 90, 90), kBackground(40, 30, 20), kSkin(120, 150, 200),
    kScreen(200, 90, 40);

// 160×128 image. Object: x 40..119, y 50..119 at 0.5 m. Virtual finger: x 60..79, y 20..99.
// Real finger (matte): the virtual one shifted right by `shift` px.
struct Scene {
  RenderTargets virt;
  cv::Mat real_bgr, real_fg, alpha;
};

Scene make_scene(float finger_depth, int shift) {
  Scene s;
  const cv::Size size(160, 128);
  s.virt.colour = cv::Mat(size, CV_8UC3, kBackground);
  s.virt.depth = cv::Mat(size, CV_32FC1, kInf);
  s.virt.hand_depth = cv::Mat(size, CV_32FC1, kInf);
  s.virt.hand_id = cv::Mat(size, CV_8UC1, cv::Scalar(0));
  const cv::Rect object(40, 50, 80, 70), finger(60, 20, 20, 80);
  s.virt.colour(object).setTo(kObject);
  s.virt.depth(object).setTo(0.5f);
  s.virt.hand_depth(finger).setTo(finger_depth);
  s.virt.hand_id(finger).setTo(encode_hand_id(1, 1));
  const cv::Rect real = finger + cv::Point(shift, 0);
  s.real_bgr = cv::Mat(size, CV_8UC3, kScreen);
  s.real_bgr(real).setTo(kSkin);
  s.real_fg = s.real_bgr.clone();
  s.alpha = cv::Mat(size, CV_32FC1, 0.f);
  s.alpha(real).setTo(1.f);
  return s;
}

cv::Mat compose(const Scene& s, CompositeMode mode, CompositorParams p = {}) {
  p.mode = mode;
  Compositor c(p);
  cv::Mat out;
  const auto status =
      c.compose({&s.virt, mode == CompositeMode::kDepth ? s.real_fg : s.real_bgr, s.alpha}, &out);
  EXPECT_TRUE(status.ok()) << status.error().message;
  return out;
}

TEST(Compositor, DepthModeHandInFrontShowsTheWholeRealFingerDespiteTheOffset) {
  const Scene s = make_scene(0.4f, 4);
  const cv::Mat out = compose(s, CompositeMode::kDepth);
  // Inside the real finger, away from its soft edges: skin everywhere, including the 4 px
  // beyond the virtual silhouette (x 80..83) over the object, where the paper mode cuts it.
  for (int y = 22; y < 98; ++y)
    for (int x = 66; x < 82; ++x) ASSERT_EQ(out.at<cv::Vec3b>(y, x), kSkin) << x << "," << y;
  // Where the virtual finger is but the real one is not (x 60..63): the scene, no hole.
  for (int y = 60; y < 98; ++y)
    for (int x = 60; x < 63; ++x) ASSERT_EQ(out.at<cv::Vec3b>(y, x), kObject) << x << "," << y;
  // Elsewhere untouched.
  EXPECT_EQ(out.at<cv::Vec3b>(5, 5), kBackground);
  EXPECT_EQ(out.at<cv::Vec3b>(110, 45), kObject);
}

TEST(Compositor, DepthModeHandBehindIsHiddenByTheObjectOnly) {
  const Scene s = make_scene(0.6f, 4);
  const cv::Mat out = compose(s, CompositeMode::kDepth);
  // Over the object (y ≥ 50): the object wins, also in the offset strip.
  for (int y = 52; y < 100; ++y)
    for (int x = 64; x < 84; ++x) ASSERT_EQ(out.at<cv::Vec3b>(y, x), kObject) << x << "," << y;
  // Above the object (empty scene, y < 48): the real finger shows.
  for (int y = 20; y < 47; ++y)
    for (int x = 66; x < 82; ++x) ASSERT_EQ(out.at<cv::Vec3b>(y, x), kSkin) << x << "," << y;
}

TEST(Compositor, DepthModeEdgesAreSoft) {
  const Scene s = make_scene(0.6f, 0);
  CompositorParams p;
  p.mode = CompositeMode::kDepth;
  Compositor c(p);
  cv::Mat out;
  ASSERT_TRUE(c.compose({&s.virt, s.real_fg, s.alpha}, &out).ok());
  // Across the occluding edge of the object (y = 50) the alpha steps down gradually.
  const float above = c.last_alpha().at<float>(48, 70), at = c.last_alpha().at<float>(50, 70);
  const float mid = c.last_alpha().at<float>(49, 70);
  EXPECT_FLOAT_EQ(above, 1.f);
  EXPECT_GT(mid, 0.f);
  EXPECT_LT(mid, 1.f);
  EXPECT_LT(at, mid);
  EXPECT_FLOAT_EQ(c.last_alpha().at<float>(52, 70), 0.f);
}

TEST(Compositor, DepthCarriedFromBlocksAgreesWithFullResolutionAwayFromTheCrossing) {
  // A tilted virtual finger: its depth runs from 0.45 m (y = 20) to 0.55 m (y = 99), crossing
  // the object's 0.5 m at y = 60; the real finger is 5 px to the right (odd, so blocks straddle).
  Scene s = make_scene(0.5f, 5);
  for (int y = 20; y < 100; ++y)
    for (int x = 60; x < 80; ++x) s.virt.hand_depth.at<float>(y, x) = 0.45f + 0.1f * static_cast<float>(y - 20) / 80.f;
  CompositorParams full, blocks;
  full.carry_downsample = 1;
  blocks.carry_downsample = 2;
  Compositor a(full), b(blocks);
  cv::Mat out_a, out_b;
  ASSERT_TRUE(a.compose({&s.virt, s.real_fg, s.alpha}, &out_a).ok());
  ASSERT_TRUE(b.compose({&s.virt, s.real_fg, s.alpha}, &out_b).ok());
  int differ = 0;
  for (int y = 0; y < out_a.rows; ++y) {
    for (int x = 0; x < out_a.cols; ++x) {
      if (std::abs(a.last_alpha().at<float>(y, x) - b.last_alpha().at<float>(y, x)) < 1e-6f) continue;
      ++differ;
      EXPECT_LE(std::abs(y - 60), 3) << "differs far from the crossing at " << x << "," << y;
    }
  }
  EXPECT_LE(differ, 3 * 20);  // at most three rows of the 20 px wide finger
  // Both show the finger over the object above the crossing and hide it below.
  EXPECT_EQ(out_b.at<cv::Vec3b>(55, 72), kSkin);
  EXPECT_EQ(out_b.at<cv::Vec3b>(66, 72), kObject);
  // A bad setting is refused, naming it.
  CompositorParams bad;
  bad.carry_downsample = 3;
  const auto st = validate(bad);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("carry_downsample"), std::string::npos);
}

TEST(Compositor, PaperModeCutsOutTheVirtualHand) {
  const Scene s = make_scene(0.4f, 4);
  const cv::Mat out = compose(s, CompositeMode::kPaper);
  // The virtual finger's pixels show the camera image: skin where the real finger is, the blue
  // screen in the 4 px it misses (the paper's registration artefact) ...
  EXPECT_EQ(out.at<cv::Vec3b>(70, 70), kSkin);
  EXPECT_EQ(out.at<cv::Vec3b>(70, 61), kScreen);
  // ... and the real finger is cut off beyond the virtual silhouette, over the object.
  EXPECT_EQ(out.at<cv::Vec3b>(70, 82), kObject);
  // Behind the object, the virtual hand is not front-most: the object stays.
  const Scene behind = make_scene(0.6f, 0);
  const cv::Mat out2 = compose(behind, CompositeMode::kPaper);
  EXPECT_EQ(out2.at<cv::Vec3b>(70, 70), kObject);
  EXPECT_EQ(out2.at<cv::Vec3b>(30, 70), kSkin);
}

TEST(Compositor, UnmatchedRealPixelsFollowThePolicy) {
  Scene s = make_scene(0.6f, 0);
  // A blob of real "hand" far (> max_carry_px) from the virtual one, over the object.
  s.alpha(cv::Rect(110, 100, 6, 6)).setTo(1.f);
  s.real_fg(cv::Rect(110, 100, 6, 6)).setTo(kSkin);
  CompositorParams p;
  p.max_carry_px = 10;
  p.show_unmatched = true;
  EXPECT_EQ(compose(s, CompositeMode::kDepth, p).at<cv::Vec3b>(103, 113), kSkin);
  p.show_unmatched = false;
  EXPECT_EQ(compose(s, CompositeMode::kDepth, p).at<cv::Vec3b>(103, 113), kObject);
}

TEST(Compositor, ErrorsNameTheInput) {
  Scene s = make_scene(0.4f, 0);
  Compositor c;
  cv::Mat out;
  auto e1 = c.compose({nullptr, s.real_fg, s.alpha}, &out);
  ASSERT_FALSE(e1.ok());
  EXPECT_NE(e1.error().message.find("virt"), std::string::npos);
  auto e2 = c.compose({&s.virt, cv::Mat(10, 10, CV_8UC3), s.alpha}, &out);
  ASSERT_FALSE(e2.ok());
  EXPECT_NE(e2.error().message.find("160x128"), std::string::npos) << e2.error().message;
  auto e3 = c.compose({&s.virt, s.real_fg, cv::Mat()}, &out);
  ASSERT_FALSE(e3.ok());
  EXPECT_NE(e3.error().message.find("matte"), std::string::npos);
  CompositorParams bad;
  bad.max_carry_px = 0;
  EXPECT_FALSE(validate(bad).ok());
  EXPECT_FALSE(parse_composite_mode("alpha").ok());
  EXPECT_EQ(*parse_composite_mode("paper"), CompositeMode::kPaper);
}

}  // namespace
}  // namespace spidar::render
