#include "spidar/vision/lens_undistortion.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "opencv_interop.hpp"

namespace spidar::vision {
namespace {

cv::Mat k_of(const Intrinsics& in) {
  return (cv::Mat_<double>(3, 3) << in.fx, 0.0, in.cx, 0.0, in.fy, in.cy, 0.0, 0.0, 1.0);
}

std::string coefficients(const Distortion& d) {
  std::ostringstream s;
  s << "k1 " << d.k1 << ", k2 " << d.k2 << ", p1 " << d.p1 << ", p2 " << d.p2 << ", k3 " << d.k3;
  return s.str();
}

/// The largest distorted normalised radius the sensor sees (its farthest corner).
double corner_radius(const Intrinsics& in) {
  double r = 0;
  for (const double u : {-0.5, in.width - 0.5})
    for (const double v : {-0.5, in.height - 0.5}) r = std::max(r, std::hypot((u - in.cx) / in.fx, (v - in.cy) / in.fy));
  return r;
}

}  // namespace

Result<Intrinsics> LensUndistortion::pinhole_of(const Intrinsics& lens) {
  if (auto st = validate_intrinsics(lens); !st) return st.error();
  const Distortion& d = lens.distortion;
  // The radial mapping r ↦ r (1 + k1 r² + k2 r⁴ + k3 r⁶) must rise until it reaches the sensor's
  // corner: where it turns back, two directions of sight meet at one pixel.
  const double r_corner = corner_radius(lens);
  constexpr double kStep = 1e-3, kMaxRadius = 10.0;  // normalised radii (10: 84° off axis)
  double r = 0;
  for (;; r += kStep) {
    const double r2 = r * r;
    const double rd = r * (1 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3)));
    if (rd >= r_corner) break;
    const double slope = 1 + r2 * (3 * d.k1 + r2 * (5 * d.k2 + r2 * 7 * d.k3));
    if (!(slope > 0) || r > kMaxRadius) {
      std::ostringstream m;
      m << "lens distortion (" << coefficients(d) << ") folds the image: its radial mapping turns back at "
        << std::atan(r) * 180.0 / 3.14159265358979 << "° off the axis, before the sensor's corner; "
        << "a real lens does not (recalibrate, or check the coefficients' order: k1, k2, p1, p2, k3)";
      return Error{m.str()};
    }
  }
  const cv::Mat K = k_of(lens), D = detail::distortion_to_cv(d);
  const cv::Size size(lens.width, lens.height);
  cv::Mat K1;
  try {
    K1 = cv::getOptimalNewCameraMatrix(K, D, size, 0.0, size, nullptr, false);
  } catch (const cv::Exception& e) {
    return Error{std::string("lens distortion: OpenCV failed: ") + e.what()};
  }
  Intrinsics p = lens;
  p.distortion = Distortion{};
  p.fx = K1.at<double>(0, 0);
  p.fy = K1.at<double>(1, 1);
  p.cx = K1.at<double>(0, 2);
  p.cy = K1.at<double>(1, 2);
  if (!(std::isfinite(p.fx) && std::isfinite(p.fy) && std::isfinite(p.cx) && std::isfinite(p.cy)) ||
      !(p.fx > 0 && p.fy > 0 && p.fx <= 2 * lens.fx && p.fy <= 2 * lens.fy) || !validate_intrinsics(p).ok()) {
    std::ostringstream m;
    m << "lens distortion (" << coefficients(d) << "): a pinhole view the sensor sees whole would have fx "
      << p.fx << " px against the lens's " << lens.fx << ", less than half of its field of view; "
      << "a real lens's calibration does not (recalibrate)";
    return Error{m.str()};
  }
  return p;
}

Status LensUndistortion::check(const Intrinsics& lens) {
  if (auto p = pinhole_of(lens); !p) return p.error();
  return Ok{};
}

Result<std::optional<LensUndistortion>> LensUndistortion::of(const Intrinsics& calibration) {
  if (calibration.distortion.is_zero()) return std::optional<LensUndistortion>{};
  auto lens = create(calibration);
  if (!lens) return lens.error();
  return std::optional<LensUndistortion>(std::move(lens).value());
}

Result<LensUndistortion> LensUndistortion::create(const Intrinsics& lens) {
  auto p = pinhole_of(lens);
  if (!p) return p.error();
  LensUndistortion out;
  out.lens_ = lens;
  out.pinhole_ = p.value();
  const cv::Mat K = k_of(lens), D = detail::distortion_to_cv(lens.distortion), K1 = k_of(out.pinhole_);
  const cv::Size size(lens.width, lens.height);
  cv::initUndistortRectifyMap(K, D, cv::noArray(), K1, size, CV_16SC2, out.undistort_xy_, out.undistort_frac_);
  // The inverse (sensor pixel → pinhole image) by OpenCV's iterative undistortion of every
  // sensor pixel, run to convergence (cv::initInverseRectificationMap's default 5 iterations
  // leave 0.35 px at a webcam's corners).
  cv::Mat sensor_px(size.height * size.width, 1, CV_64FC2), pinhole_px;
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) sensor_px.at<cv::Vec2d>(v * size.width + u) = cv::Vec2d(u, v);
  cv::undistortPoints(sensor_px, pinhole_px, K, D, cv::noArray(), K1,
                      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-10));
  cv::Mat map_xy;
  pinhole_px.reshape(2, size.height).convertTo(map_xy, CV_32FC2);
  cv::convertMaps(map_xy, cv::noArray(), out.distort_xy_, out.distort_frac_, CV_16SC2);
  return out;
}

void LensUndistortion::undistort(const cv::Mat& sensor, cv::Mat* pinhole_image) const {
  cv::remap(sensor, *pinhole_image, undistort_xy_, undistort_frac_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
}

void LensUndistortion::distort(const cv::Mat& pinhole_image, cv::Mat* sensor, const cv::Scalar& outside) const {
  cv::remap(pinhole_image, *sensor, distort_xy_, distort_frac_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, outside);
}

Vec2 LensUndistortion::to_pinhole(const Vec2& sensor_px) const {
  const cv::Mat src = (cv::Mat_<cv::Vec2d>(1, 1) << cv::Vec2d(sensor_px.x(), sensor_px.y()));
  cv::Mat dst;
  cv::undistortPoints(src, dst, k_of(lens_), detail::distortion_to_cv(lens_.distortion), cv::noArray(),
                      k_of(pinhole_), cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-10));
  const cv::Vec2d q = dst.at<cv::Vec2d>(0, 0);
  return {q[0], q[1]};
}

Vec2 LensUndistortion::to_sensor(const Vec2& pinhole_px) const {
  const Camera lens_camera(lens_, Pose{});
  return lens_camera.project_camera(
      Vec3((pinhole_px.x() - pinhole_.cx) / pinhole_.fx, (pinhole_px.y() - pinhole_.cy) / pinhole_.fy, 1.0));
}

}  // namespace spidar::vision
