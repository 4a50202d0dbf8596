// vision::LensUndistortion against the camera's own projection (vision::Camera, which implements
// the distortion formula itself): a dot filmed through the lens must land, once undistorted,
// where the pinhole camera projects the same ray; and the reverse for the simulated lens.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "spidar/vision/camera.hpp"
#include "spidar/vision/lens_undistortion.hpp"

namespace spidar::vision {
namespace {

/// A webcam's barrel lens at 640×480 (corners moved by about 25 px).
Intrinsics webcam() {
  Intrinsics k;
  k.distortion = {-0.28, 0.09, 0.0008, -0.0005, 0.0};
  return k;
}

/// A Gaussian dot (σ 1.5 px) at `at` [px] on a black float image of `in`'s size.
cv::Mat dot(const Intrinsics& in, const Vec2& at) {
  cv::Mat img(in.height, in.width, CV_32FC1, cv::Scalar(0));
  for (int v = 0; v < in.height; ++v)
    for (int u = 0; u < in.width; ++u) {
      const double d2 = (u - at.x()) * (u - at.x()) + (v - at.y()) * (v - at.y());
      if (d2 < 100) img.at<float>(v, u) = static_cast<float>(std::exp(-d2 / (2 * 1.5 * 1.5)));
    }
  return img;
}

Vec2 centroid(const cv::Mat& img) {
  const cv::Moments m = cv::moments(img);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

/// Rays spread over the pinhole view, out to 90 % of its half extents.
std::vector<Vec3> rays(const Intrinsics& pinhole) {
  std::vector<Vec3> out;
  for (const double a : {-0.9, -0.5, 0.0, 0.4, 0.9})
    for (const double b : {-0.9, -0.3, 0.0, 0.6, 0.9}) {
      const double u = pinhole.cx + a * 0.5 * pinhole.width, v = pinhole.cy + b * 0.5 * pinhole.height;
      out.emplace_back((u - pinhole.cx) / pinhole.fx, (v - pinhole.cy) / pinhole.fy, 1.0);
    }
  return out;
}

TEST(LensUndistortion, ADotFilmedThroughTheLensLandsWhereThePinholeCameraProjectsItsRay) {
  const auto lens = LensUndistortion::create(webcam());
  ASSERT_TRUE(lens) << lens.error().message;
  const Camera distorted(lens->lens(), Pose{}), pinhole(lens->pinhole(), Pose{});
  double worst = 0, moved = 0;
  for (const Vec3& ray : rays(lens->pinhole())) {
    const Vec2 seen = distorted.project_camera(ray), want = pinhole.project_camera(ray);
    moved = std::max(moved, (seen - want).norm());
    cv::Mat out;
    lens->undistort(dot(lens->lens(), seen), &out);
    worst = std::max(worst, (centroid(out) - want).norm());
    EXPECT_LT((lens->to_pinhole(seen) - want).norm(), 1e-3) << ray.transpose();
    EXPECT_LT((lens->to_sensor(want) - seen).norm(), 1e-6) << ray.transpose();
  }
  std::printf("undistorted dots within %.3f px of the pinhole projection (the lens moved them up to %.1f px)\n",
              worst, moved);
  EXPECT_GT(moved, 10.0);  // the lens matters: the test could fail
  EXPECT_LT(worst, 0.15);
}

TEST(LensUndistortion, TheSimulatedLensPutsADotWhereTheLensProjectsItsRay) {
  const auto lens = LensUndistortion::create(webcam());
  ASSERT_TRUE(lens) << lens.error().message;
  const Camera distorted(lens->lens(), Pose{}), pinhole(lens->pinhole(), Pose{});
  double worst = 0;
  for (const Vec3& ray : rays(lens->pinhole())) {
    cv::Mat out;
    lens->distort(dot(lens->pinhole(), pinhole.project_camera(ray)), &out, cv::Scalar(0));
    worst = std::max(worst, (centroid(out) - distorted.project_camera(ray)).norm());
  }
  std::printf("distorted dots within %.3f px of the lens's projection\n", worst);
  EXPECT_LT(worst, 0.15);
}

TEST(LensUndistortion, EveryPinholePixelIsSeenByTheSensor) {
  const auto lens = LensUndistortion::create(webcam());
  ASSERT_TRUE(lens) << lens.error().message;
  const Intrinsics& p = lens->pinhole();
  for (const double u : {0.0, p.width - 1.0})
    for (const double v : {0.0, p.height - 1.0}) {
      const Vec2 s = lens->to_sensor({u, v});
      EXPECT_GE(s.x(), -0.5 - 1e-3) << u << "," << v;
      EXPECT_LE(s.x(), p.width - 0.5 + 1e-3) << u << "," << v;
      EXPECT_GE(s.y(), -0.5 - 1e-3) << u << "," << v;
      EXPECT_LE(s.y(), p.height - 0.5 + 1e-3) << u << "," << v;
    }
  // A pincushion lens too (the pinhole view then narrower than the lens's).
  Intrinsics pin = webcam();
  pin.distortion = {0.15, 0.0, 0.0, 0.0, 0.0};
  const auto l2 = LensUndistortion::create(pin);
  ASSERT_TRUE(l2) << l2.error().message;
  EXPECT_GT(l2->pinhole().fx, pin.fx);
  const Vec2 corner = l2->to_sensor({0.0, 0.0});
  EXPECT_GE(corner.x(), -0.5 - 1e-3);
  EXPECT_GE(corner.y(), -0.5 - 1e-3);
}

TEST(LensUndistortion, RefusesALensThatFoldsTheImageAndSaysWhy) {
  Intrinsics k = webcam();
  k.distortion = {-1.5, 0.0, 0.0, 0.0, 0.0};  // r(1 − 1.5 r²) turns back at r = 0.47, inside the corner (0.72)
  const auto lens = LensUndistortion::create(k);
  ASSERT_FALSE(lens);
  EXPECT_NE(lens.error().message.find("folds the image"), std::string::npos) << lens.error().message;
  EXPECT_NE(lens.error().message.find("k1 -1.5"), std::string::npos) << lens.error().message;
  k.distortion = {50, 0, 0, 0, 0};  // pincushion so strong the whole view shrinks to a peephole
  const auto strong = LensUndistortion::create(k);
  ASSERT_FALSE(strong);
  EXPECT_NE(strong.error().message.find("field of view"), std::string::npos) << strong.error().message;
}

}  // namespace
}  // namespace spidar::vision
