// Chroma key on drawn hands over a blue screen with uneven light, shadows, soft edges and noise.
#include <gtest/gtest.h>

#include "spidar/vision/chroma_key.hpp"
#include "spidar/vision/vision_config.hpp"
#include "synthetic_scene.hpp"

namespace spidar::vision {
namespace {

using test::DrawnHand;
using test::SceneOptions;

double iou(const cv::Mat& silhouette, const cv::Mat& coverage) {
  cv::Mat truth = coverage >= 0.5f;
  cv::Mat sil = silhouette > 0;
  const double inter = cv::countNonZero(truth & sil);
  const double uni = cv::countNonZero(truth | sil);
  return inter / uni;
}

std::vector<DrawnHand> two_hands() {
  return {DrawnHand{{190, 400}, -1.75, 170}, DrawnHand{{450, 390}, -1.35, 170}};
}

TEST(ChromaKey, MatteMatchesDrawnHandsUnderUnevenLightAndShadows) {
  for (double light_min : {1.0, 0.45, 0.25}) {
    SceneOptions o;
    o.light_min = light_min;
    o.seed = static_cast<unsigned>(light_min * 100);
    const auto scene = test::draw_scene(two_hands(), o);
    ChromaKeyResult r;
    ASSERT_TRUE(chroma_key(scene.bgr, ChromaKeyParams{}, &r).ok());
    const double j = iou(r.silhouette, scene.coverage);
    cv::Mat diff;
    cv::absdiff(r.alpha, scene.coverage, diff);
    const double mae = cv::mean(diff)[0];
    std::printf("light %.2f..1: silhouette IoU %.4f, matte mean abs error %.4f\n", light_min, j, mae);
    RecordProperty("iou_light_" + std::to_string(static_cast<int>(light_min * 100)), std::to_string(j));
    EXPECT_GT(j, 0.98);
    EXPECT_LT(mae, 0.01);
  }
}

TEST(ChromaKey, SoftEdgesFollowCoverage) {
  const auto scene = test::draw_scene(two_hands());
  ChromaKeyResult r;
  ASSERT_TRUE(chroma_key(scene.bgr, ChromaKeyParams{}, &r).ok());
  // On edge pixels (partial coverage) the matte is soft and rises with coverage.
  double low = 0, high = 0;
  int n_low = 0, n_high = 0;
  for (int y = 0; y < scene.coverage.rows; ++y)
    for (int x = 0; x < scene.coverage.cols; ++x) {
      const float c = scene.coverage.at<float>(y, x);
      if (c > 0.1f && c < 0.35f) { low += r.alpha.at<float>(y, x); ++n_low; }
      if (c > 0.65f && c < 0.9f) { high += r.alpha.at<float>(y, x); ++n_high; }
    }
  ASSERT_GT(n_low, 50);
  ASSERT_GT(n_high, 50);
  EXPECT_LT(low / n_low, high / n_high);
  EXPECT_GT(high / n_high, 0.5);
}

TEST(ChromaKey, BlueSpillIsRemovedOnEdgesOnly) {
  SceneOptions o;
  o.spill = 60;
  const auto scene = test::draw_scene(two_hands(), o);
  ChromaKeyResult r;
  ASSERT_TRUE(chroma_key(scene.bgr, ChromaKeyParams{}, &r).ok());
  int spill_before = 0, spill_after = 0, interior_changed = 0;
  for (int y = 0; y < scene.bgr.rows; ++y)
    for (int x = 0; x < scene.bgr.cols; ++x) {
      const float a = r.alpha.at<float>(y, x);
      const auto in = scene.bgr.at<cv::Vec3b>(y, x), out = r.foreground.at<cv::Vec3b>(y, x);
      if (a > 0.f && a < 1.f) {
        spill_before += in[0] > std::max(in[1], in[2]);
        spill_after += out[0] > std::max(out[1], out[2]);
      }
      if (scene.coverage.at<float>(y, x) == 1.f && a == 1.f) {
        bool edge = false;
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int yy = std::clamp(y + dy, 0, scene.bgr.rows - 1), xx = std::clamp(x + dx, 0, scene.bgr.cols - 1);
            edge = edge || r.alpha.at<float>(yy, xx) < 1.f;
          }
        if (!edge) interior_changed += in != out;
      }
    }
  EXPECT_GT(spill_before, 100);
  EXPECT_EQ(spill_after, 0);
  EXPECT_EQ(interior_changed, 0);
}

TEST(ChromaKey, EmptyScreenGivesEmptySilhouette) {
  const auto scene = test::draw_scene({}, SceneOptions{});
  ChromaKeyResult r;
  ASSERT_TRUE(chroma_key(scene.bgr, ChromaKeyParams{}, &r).ok());
  EXPECT_EQ(cv::countNonZero(r.silhouette), 0);
}

TEST(ChromaKey, BadInputAndParamsAreErrors) {
  ChromaKeyResult r;
  EXPECT_FALSE(chroma_key(cv::Mat(), ChromaKeyParams{}, &r).ok());
  EXPECT_FALSE(chroma_key(cv::Mat(10, 10, CV_8UC1), ChromaKeyParams{}, &r).ok());
  ChromaKeyParams p;
  p.s_foreground = 0.5;
  const auto s = chroma_key(cv::Mat(10, 10, CV_8UC3, cv::Scalar(0)), p, &r);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("s_foreground < s_background"), std::string::npos);
}

TEST(VisionConfig, ShippedFileHasTheDefaults) {
  const auto cfg = load_vision_config(std::string(SPIDAR_SOURCE_DIR) + "/configs/vision.yaml");
  const ChromaKeyParams d;
  EXPECT_EQ(cfg.chroma_key.s_foreground, d.s_foreground);
  EXPECT_EQ(cfg.chroma_key.s_background, d.s_background);
  EXPECT_EQ(cfg.chroma_key.cleanup_radius_px, d.cleanup_radius_px);
  const BraceletParams b;
  EXPECT_EQ(cfg.bracelet.saturation_min, b.saturation_min);
  EXPECT_EQ(cfg.bracelet.hue_high_min, b.hue_high_min);
  try {
    parse_vision_config(core::ConfigNode::Parse("chroma_key:\n  s_foreground: 0.6\n", "v.yaml"));
    FAIL();
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("v.yaml:2: chroma_key"), std::string::npos) << e.what();
  }
  // The cleanup radius is quoted as written, not as clamped for the check.
  for (const char* radius : {"100", "1000000000", "-5"}) {
    try {
      parse_vision_config(core::ConfigNode::Parse(std::string("chroma_key:\n  cleanup_radius_px: ") + radius + "\n", "v.yaml"));
      FAIL() << radius;
    } catch (const core::ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), std::string("v.yaml:2: chroma_key.cleanup_radius_px: expected 0..10, got ") + radius);
    }
  }
  try {
    parse_vision_config(core::ConfigNode::Parse("bracelet:\n  hue_low: 3\n", "v.yaml"));
    FAIL();
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("hue_low"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace spidar::vision
