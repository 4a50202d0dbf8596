#pragma once
// Conversions between Eigen/spidar types and OpenCV (private to the vision module).
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "spidar/core/pose.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision::detail {

inline cv::Mat to_cv(const Mat3& M) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = M(r, c);
  return out;
}

inline cv::Mat distortion_to_cv(const Distortion& d) {
  return (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
}

inline Distortion distortion_from_cv(const cv::Mat& d) {
  cv::Mat v;
  d.convertTo(v, CV_64F);
  v = v.reshape(1, 1);
  Distortion out;
  const int n = v.cols;
  auto at = [&](int i) { return i < n ? v.at<double>(0, i) : 0.0; };
  out = {at(0), at(1), at(2), at(3), at(4)};
  return out;
}

/// X_CW from OpenCV's rvec/tvec (which map object/world points into the camera frame).
inline Pose pose_from_rvec_tvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  R.convertTo(R, CV_64F);
  cv::Mat t;
  tvec.convertTo(t, CV_64F);
  Mat3 R_e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R_e(r, c) = R.at<double>(r, c);
  return {Quat(R_e).normalized(), Vec3(t.at<double>(0), t.at<double>(1), t.at<double>(2))};
}

}  // namespace spidar::vision::detail
