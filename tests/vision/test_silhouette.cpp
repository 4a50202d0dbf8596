// Distance transform labels against brute force; bilinear matte sampling.
#include <gtest/gtest.h>

#include <limits>
#include <opencv2/imgproc.hpp>
#include <cstdint>
#include <random>

#include "spidar/vision/silhouette.hpp"

namespace spidar::vision {
namespace {

TEST(Silhouette, NearestPixelLabelsAgreeWithBruteForce) {
  std::mt19937 rng(21);
  double worst_excess = 0;
  for (int trial = 0; trial < 20; ++trial) {
    cv::Mat sil(37 + trial, 53 - trial, CV_8UC1, cv::Scalar(0));
    std::uniform_int_distribution<int> ux(0, sil.cols - 1), uy(0, sil.rows - 1), ur(1, 6);
    const int blobs = 1 + trial % 4;
    for (int b = 0; b < blobs; ++b) cv::circle(sil, {ux(rng), uy(rng)}, ur(rng), cv::Scalar(255), -1);
    if (trial % 5 == 0) sil.at<uchar>(uy(rng), ux(rng)) = 255;  // single pixels too
    std::vector<cv::Point> on;
    cv::findNonZero(sil, on);
    SilhouetteDistance d;
    ASSERT_TRUE(silhouette_distance(sil, &d).ok());
    ASSERT_FALSE(d.empty);
    for (int y = 0; y < sil.rows; ++y) {
      for (int x = 0; x < sil.cols; ++x) {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& p : on) best = std::min(best, std::hypot(p.x - x, p.y - y));
        const auto n = d.nearest(x, y);
        ASSERT_TRUE(n.has_value());
        ASSERT_NE(sil.at<uchar>(n->y, n->x), 0) << "label points off the silhouette";
        const double got = std::hypot(n->x - x, n->y - y);
        if (sil.at<uchar>(y, x)) {
          ASSERT_EQ(got, 0.0);
        }
        worst_excess = std::max(worst_excess, got - best);
        // OpenCV's 5x5 mask propagates labels approximately: allow a small excess.
        ASSERT_LE(got, best * 1.05 + 0.5) << "at " << x << "," << y;
        EXPECT_NEAR(d.distance.at<float>(y, x), best, 0.03 * best + 0.05);
      }
    }
  }
  std::printf("distance transform: nearest-label distance exceeds the true minimum by at most %.3f px\n",
              worst_excess);
  RecordProperty("label_excess_max_px", std::to_string(worst_excess));
}

TEST(Silhouette, MarginRoiAgreesNearTheSilhouette) {
  cv::Mat sil(120, 160, CV_8UC1, cv::Scalar(0));
  cv::circle(sil, {60, 70}, 15, cv::Scalar(255), -1);
  cv::rectangle(sil, cv::Rect(95, 40, 20, 30), cv::Scalar(255), -1);
  SilhouetteDistance full, near;
  ASSERT_TRUE(silhouette_distance(sil, &full).ok());
  ASSERT_TRUE(silhouette_distance(sil, &near, {.max_distance_px = 10}).ok());
  EXPECT_EQ(near.roi, cv::Rect(35, 30, 90, 66));
  for (int y = near.roi.y; y < near.roi.y + near.roi.height; ++y)
    for (int x = near.roi.x; x < near.roi.x + near.roi.width; ++x) {
      if (full.distance.at<float>(y, x) > 8.0f) continue;  // near the silhouette: identical
      ASSERT_EQ(*near.nearest(x, y), *full.nearest(x, y)) << x << "," << y;
    }
  // Far outside the roi a query is clamped into it: still a silhouette pixel.
  const auto far = near.nearest(Vec2(0, 0));
  ASSERT_TRUE(far.has_value());
  EXPECT_NE(sil.at<uchar>(static_cast<int>(far->y()), static_cast<int>(far->x())), 0);
  EXPECT_FALSE(near.nearest(0, 0).has_value());
}

TEST(Silhouette, HalfResolutionLabelsStayClose) {
  std::mt19937 rng(33);
  double worst_excess = 0;
  for (int trial = 0; trial < 10; ++trial) {
    cv::Mat sil(41 + trial, 57 - trial, CV_8UC1, cv::Scalar(0));
    std::uniform_int_distribution<int> ux(0, sil.cols - 1), uy(0, sil.rows - 1), ur(1, 6);
    for (int b = 0; b < 1 + trial % 3; ++b) cv::circle(sil, {ux(rng), uy(rng)}, ur(rng), cv::Scalar(255), -1);
    sil.at<uchar>(uy(rng), ux(rng)) = 255;
    std::vector<cv::Point> on;
    cv::findNonZero(sil, on);
    SilhouetteDistance d;
    ASSERT_TRUE(silhouette_distance(sil, &d, {.max_distance_px = 0, .downsample = 2}).ok());
    for (int y = 0; y < sil.rows; ++y)
      for (int x = 0; x < sil.cols; ++x) {
        double best = std::numeric_limits<double>::infinity();
        for (const auto& p : on) best = std::min(best, std::hypot(p.x - x, p.y - y));
        const auto n = d.nearest(x, y);
        ASSERT_TRUE(n.has_value());
        ASSERT_NE(sil.at<uchar>(n->y, n->x), 0);
        const double got = std::hypot(n->x - x, n->y - y);
        worst_excess = std::max(worst_excess, got - best);
        ASSERT_LE(got, best * 1.05 + 2.5) << "at " << x << "," << y;
      }
  }
  std::printf("half-resolution distance transform: nearest-label excess at most %.3f px\n", worst_excess);
  RecordProperty("half_res_label_excess_max_px", std::to_string(worst_excess));
}

TEST(Silhouette, SubPixelQueriesAndEmptySilhouettes) {
  cv::Mat sil(20, 30, CV_8UC1, cv::Scalar(0));
  sil(cv::Rect(10, 5, 4, 3)).setTo(255);
  SilhouetteDistance d;
  ASSERT_TRUE(silhouette_distance(sil, &d).ok());
  EXPECT_EQ(*d.nearest(Vec2(2.2, 6.4)), Vec2(10, 6));
  EXPECT_NEAR(d.distance_at(Vec2(2.2, 6.4)), std::hypot(7.8, 0.4), 1e-12);
  EXPECT_EQ(*d.nearest(Vec2(-50, 200)), Vec2(10, 7));  // clamped into the image first
  cv::Mat none(20, 30, CV_8UC1, cv::Scalar(0));
  ASSERT_TRUE(silhouette_distance(none, &d).ok());
  EXPECT_TRUE(d.empty);
  EXPECT_FALSE(d.nearest(Vec2(3, 3)).has_value());
  EXPECT_TRUE(std::isinf(d.distance_at(Vec2(3, 3))));
  EXPECT_FALSE(silhouette_distance(cv::Mat(), &d).ok());
}

TEST(Silhouette, BilinearSamplingMatchesOpenCvRemap) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  cv::Mat alpha(24, 32, CV_32FC1);
  for (int y = 0; y < alpha.rows; ++y)
    for (int x = 0; x < alpha.cols; ++x) alpha.at<float>(y, x) = u01(rng);
  std::uniform_real_distribution<double> ux(-2.0, 33.0), uy(-2.0, 25.0);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(ux(rng), uy(rng));
    cv::Mat mx(1, 1, CV_32FC1, cv::Scalar(p.x())), my(1, 1, CV_32FC1, cv::Scalar(p.y())), out;
    cv::remap(alpha, out, mx, my, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));
    // remap uses 5-bit fixed-point interpolation weights: agree to ~1/32 of the local range.
    EXPECT_NEAR(sample_bilinear(alpha, p), out.at<float>(0, 0), 0.035) << p.transpose();
  }
  EXPECT_FLOAT_EQ(static_cast<float>(sample_bilinear(alpha, Vec2(5, 7))), alpha.at<float>(7, 5));
  const double mid = 0.25 * (alpha.at<float>(7, 5) + alpha.at<float>(7, 6) + alpha.at<float>(8, 5) +
                             alpha.at<float>(8, 6));
  EXPECT_NEAR(sample_bilinear(alpha, Vec2(5.5, 7.5)), mid, 1e-6);
  EXPECT_EQ(sample_bilinear(alpha, Vec2(-3, 4)), 0.0);
  EXPECT_EQ(sample_bilinear(alpha, Vec2(std::nan(""), 4)), 0.0);
  cv::Mat hand(10, 10, CV_32FC1, cv::Scalar(0));
  hand(cv::Rect(0, 0, 5, 10)).setTo(1.0f);
  EXPECT_TRUE(on_silhouette(hand, Vec2(4.4, 3)));
  EXPECT_FALSE(on_silhouette(hand, Vec2(4.6, 3)));
}

// An 8-bit silhouette (255 = hand) samples exactly as its 0/1 float copy: the size estimate's
// keyframes give the joint-balls their silhouettes without converting them.
TEST(SampleBilinear, ABinarySilhouetteOfBytesSamplesAsItsFloatCopy) {
  std::mt19937 rng(7);
  std::bernoulli_distribution on(0.4);
  cv::Mat bytes(24, 32, CV_8UC1);
  for (int y = 0; y < bytes.rows; ++y)
    for (int x = 0; x < bytes.cols; ++x) bytes.at<std::uint8_t>(y, x) = on(rng) ? 255 : 0;
  cv::Mat floats;
  bytes.convertTo(floats, CV_32FC1, 1.0 / 255.0);
  std::uniform_real_distribution<double> ux(-2.0, 33.0), uy(-2.0, 25.0);
  for (int i = 0; i < 500; ++i) {
    const Vec2 p(ux(rng), uy(rng));
    EXPECT_EQ(sample_bilinear(bytes, p), sample_bilinear(floats, p)) << p.transpose();
    EXPECT_EQ(on_silhouette(bytes, p), on_silhouette(floats, p)) << p.transpose();
  }
  // Other types are no matte at all.
  EXPECT_EQ(sample_bilinear(cv::Mat(24, 32, CV_16UC1, cv::Scalar(65535)), Vec2(5, 5)), 0.0);
}


// The nearest pixel's value, against the pixel whose centre is nearest by brute force; 0 outside
// the image, for a non-finite point and for a type that is no matte.
TEST(SampleNearest, ReadsThePixelWhoseCentreIsNearest) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  cv::Mat alpha(12, 16, CV_32FC1);
  for (int y = 0; y < alpha.rows; ++y)
    for (int x = 0; x < alpha.cols; ++x) alpha.at<float>(y, x) = u01(rng);
  cv::Mat bytes;
  alpha.convertTo(bytes, CV_8UC1, 255.0);
  std::uniform_real_distribution<double> ux(-0.49, 15.49), uy(-0.49, 11.49);
  for (int i = 0; i < 300; ++i) {
    const Vec2 p(ux(rng), uy(rng));
    int bx = 0, by = 0;
    double best = 1e9;
    for (int y = 0; y < alpha.rows; ++y)
      for (int x = 0; x < alpha.cols; ++x)
        if (const double d = (p - Vec2(x, y)).squaredNorm(); d < best) best = d, bx = x, by = y;
    EXPECT_EQ(sample_nearest(alpha, p), static_cast<double>(alpha.at<float>(by, bx))) << p.transpose();
    EXPECT_EQ(sample_nearest(bytes, p), bytes.at<std::uint8_t>(by, bx) / 255.0) << p.transpose();
  }
  EXPECT_EQ(sample_nearest(alpha, Vec2(-0.6, 3)), 0.0);
  EXPECT_EQ(sample_nearest(alpha, Vec2(3, 11.6)), 0.0);
  EXPECT_EQ(sample_nearest(alpha, Vec2(15.6, 3)), 0.0);
  EXPECT_EQ(sample_nearest(alpha, Vec2(std::nan(""), 3)), 0.0);
  EXPECT_EQ(sample_nearest(alpha, Vec2(3, std::numeric_limits<double>::infinity())), 0.0);
  EXPECT_EQ(sample_nearest(alpha, Vec2(1e300, -1e300)), 0.0);
  EXPECT_EQ(sample_nearest(cv::Mat(12, 16, CV_16UC1, cv::Scalar(65535)), Vec2(5, 5)), 0.0);
  EXPECT_EQ(sample_nearest(cv::Mat(), Vec2(0, 0)), 0.0);
}

}  // namespace
}  // namespace spidar::vision
