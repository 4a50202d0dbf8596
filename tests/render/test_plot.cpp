// Line plots for the demo's report.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <opencv2/core.hpp>

#include "spidar/render/plot.hpp"

namespace spidar::render {
namespace {

// Pixels near a colour (anti-aliased lines blend with the white background at their edges).
bool near(const cv::Vec3b& p, const std::array<std::uint8_t, 3>& c) {
  return std::abs(p[0] - c[0]) + std::abs(p[1] - c[1]) + std::abs(p[2] - c[2]) < 90;
}

int count_colour(const cv::Mat& img, const std::array<std::uint8_t, 3>& c) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) n += near(img.at<cv::Vec3b>(y, x), c) ? 1 : 0;
  }
  return n;
}

TEST(Plot, DrawsEachSeriesInItsColour) {
  PlotSeries rising{"rising", {0, 1, 2, 3}, {0, 1, 2, 3}, {255, 0, 0}};
  PlotSeries flat{"flat", {0, 3}, {1.5, 1.5}, {0, 0, 255}};
  PlotSpec spec;
  spec.title = "test";
  const std::vector<PlotSeries> both{rising, flat};
  auto img = plot_lines(spec, both);
  ASSERT_TRUE(img.ok()) << img.error().message;
  EXPECT_EQ(img->cols, spec.width);
  EXPECT_EQ(img->rows, spec.height);
  // A diagonal across the panel and a horizontal line: hundreds of pixels each (plus legend).
  EXPECT_GT(count_colour(*img, rising.bgr), 300);
  EXPECT_GT(count_colour(*img, flat.bgr), 300);
  // Without the series the colours are gone.
  auto empty = plot_lines(spec, {});
  ASSERT_TRUE(empty.ok());
  EXPECT_EQ(count_colour(*empty, rising.bgr), 0);
}

TEST(Plot, RisingLineGoesUpTheImage) {
  PlotSeries rising{"rising", {0, 10}, {0, 10}, {255, 0, 0}};
  PlotSpec spec;
  auto img = plot_lines(spec, std::span<const PlotSeries>(&rising, 1));
  ASSERT_TRUE(img.ok());
  // The leftmost blue pixel of the line (inside the panel) is lower than the rightmost one.
  int left_y = -1, right_y = -1;
  for (int x = 70; x < spec.width - 170; ++x) {
    for (int y = 30; y < spec.height - 45; ++y) {
      if (near(img->at<cv::Vec3b>(y, x), {255, 0, 0})) {
        if (left_y < 0) left_y = y;
        right_y = y;
      }
    }
  }
  ASSERT_GE(left_y, 0);
  EXPECT_GT(left_y, right_y + 100);
}

TEST(Plot, BadInputIsAnErrorNamingTheSeries) {
  PlotSeries bad{"bad", {0, 1}, {0}, {0, 0, 0}};
  PlotSpec spec;
  spec.title = "p";
  auto r = plot_lines(spec, std::span<const PlotSeries>(&bad, 1));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'bad'"), std::string::npos);
  spec.width = 50;
  EXPECT_FALSE(plot_lines(spec, {}).ok());
}

}  // namespace
}  // namespace spidar::render

#include "spidar/render/composite_metrics.hpp"

namespace spidar::render {
namespace {

TEST(CompositeMetrics, CountsDisagreementsInsideTheRegionOnly) {
  const float inf = std::numeric_limits<float>::infinity();
  cv::Mat mask(4, 4, CV_8UC1, cv::Scalar(0)), depth(4, 4, CV_32FC1, cv::Scalar(inf));
  cv::Mat scene(4, 4, CV_32FC1, cv::Scalar(0.5));
  mask(cv::Rect(0, 0, 2, 4)).setTo(255);
  depth(cv::Rect(0, 0, 2, 4)).setTo(0.4);
  depth(cv::Rect(0, 0, 2, 1)).setTo(0.6);  // top row of the hand behind the scene
  cv::Mat truth;
  ASSERT_TRUE(truth_composite_mask(mask, depth, scene, &truth).ok());
  EXPECT_EQ(cv::countNonZero(truth), 6);
  cv::Mat alpha(4, 4, CV_32FC1, cv::Scalar(0));
  alpha(cv::Rect(0, 0, 2, 4)).setTo(1.0);  // shows the whole hand: 2 wrong pixels (top row)
  alpha.at<float>(3, 3) = 1.0;            // and one outside the region
  cv::Mat region(4, 4, CV_8UC1, cv::Scalar(0));
  region(cv::Rect(0, 0, 3, 4)).setTo(255);  // 12 pixels
  auto e = occlusion_error_pct(alpha, truth, region);
  ASSERT_TRUE(e.ok());
  EXPECT_DOUBLE_EQ(*e, 100.0 * 2 / 12);
  EXPECT_FALSE(occlusion_error_pct(alpha, truth, cv::Mat(3, 3, CV_8UC1)).ok());
}

TEST(CompositeMetrics, ContestedPixelsAreTheHandOverAnObjectOnly) {
  const float inf = std::numeric_limits<float>::infinity();
  // A 4x6 frame: an object (finite scene depth) in columns 2..5; the real hand in columns 0..3.
  cv::Mat hand(4, 6, CV_8UC1, cv::Scalar(0)), scene(4, 6, CV_32FC1, cv::Scalar(inf));
  hand(cv::Rect(0, 0, 4, 4)).setTo(255);
  scene(cv::Rect(2, 0, 4, 4)).setTo(0.5f);
  cv::Mat contested;
  ASSERT_TRUE(contested_mask(hand, scene, &contested).ok());
  EXPECT_EQ(cv::countNonZero(contested), 8);  // columns 2..3
  EXPECT_EQ(contested.at<std::uint8_t>(0, 1), 0);
  EXPECT_EQ(contested.at<std::uint8_t>(0, 4), 0);
  // Truth: the hand is in front in row 0 only; a composite showing the hand everywhere is wrong
  // on rows 1..3 of the contested columns (6 of 8) but right on every uncontested hand pixel.
  cv::Mat truth(4, 6, CV_8UC1, cv::Scalar(0));
  truth(cv::Rect(0, 0, 2, 4)).setTo(255);
  truth(cv::Rect(2, 0, 2, 1)).setTo(255);
  cv::Mat alpha(4, 6, CV_32FC1, cv::Scalar(0));
  alpha(cv::Rect(0, 0, 4, 4)).setTo(1.0f);
  auto d = region_disagreement(alpha, truth, contested);
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->pixels, 8);
  EXPECT_EQ(d->wrong, 6);
  EXPECT_DOUBLE_EQ(d->pct(), 75.0);
  // Over the whole hand the same composite looks far better: 6 of 16.
  auto whole = occlusion_error_pct(alpha, truth, hand);
  ASSERT_TRUE(whole.ok());
  EXPECT_DOUBLE_EQ(*whole, 100.0 * 6 / 16);
  EXPECT_FALSE(contested_mask(hand, cv::Mat(3, 3, CV_32FC1), &contested).ok());
  EXPECT_EQ(RegionDisagreement{}.pct(), 0.0);
}

TEST(CompositeMetrics, RegionDisagreementCountsAsAPixelByPixelReference) {
  // Random images (any non-zero byte counts as set, alpha with NaN and exact 0.5 values) against
  // a plain count pixel by pixel; a width that is not a multiple of any vector length.
  cv::RNG rng(7);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(37, 5), cv::Size(640, 48)}) {
    cv::Mat alpha(size, CV_32FC1), truth(size, CV_8UC1), region(size, CV_8UC1);
    rng.fill(alpha, cv::RNG::UNIFORM, 0.0, 1.0);
    rng.fill(truth, cv::RNG::UNIFORM, 0, 3);
    rng.fill(region, cv::RNG::UNIFORM, 0, 4);
    alpha.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
    if (size.width > 1) alpha.at<float>(0, 1) = 0.5f;
    long pixels = 0, wrong = 0;
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        if (region.at<std::uint8_t>(y, x) == 0) continue;
        ++pixels;
        const bool real_shown = alpha.at<float>(y, x) >= 0.5f;
        if (real_shown != (truth.at<std::uint8_t>(y, x) != 0)) ++wrong;
      }
    auto d = region_disagreement(alpha, truth, region);
    ASSERT_TRUE(d.ok());
    EXPECT_EQ(d->pixels, pixels) << size;
    EXPECT_EQ(d->wrong, wrong) << size;
  }
}

}  // namespace
}  // namespace spidar::render
