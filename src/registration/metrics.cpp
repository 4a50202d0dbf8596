#include "spidar/registration/metrics.hpp"

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::registration {

double mask_iou(const cv::Mat& a, const cv::Mat& b) {
  if (a.type() != CV_8UC1 || b.type() != CV_8UC1 || a.size() != b.size()) {
    throw SpidarError("mask_iou: expected two CV_8UC1 masks of one size, got types " +
                      std::to_string(a.type()) + " and " + std::to_string(b.type()) + ", sizes " +
                      std::to_string(a.cols) + "x" + std::to_string(a.rows) + " and " +
                      std::to_string(b.cols) + "x" + std::to_string(b.rows));
  }
  long inter = 0, uni = 0;
  for (int y = 0; y < a.rows; ++y) {
    const auto* pa = a.ptr<std::uint8_t>(y);
    const auto* pb = b.ptr<std::uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      const bool ia = pa[x] != 0, ib = pb[x] != 0;
      inter += ia && ib;
      uni += ia || ib;
    }
  }
  return uni == 0 ? 1.0 : static_cast<double>(inter) / static_cast<double>(uni);
}

double joint_px_error(const hand::HandPoints& fitted, const hand::HandPoints& truth,
                      const vision::Camera& camera) {
  double sum = 0;
  int n = 0;
  for (int j = 0; j < hand::kJointCount; ++j) {
    const Vec3& a = fitted.p_W_joint[j];
    const Vec3& b = truth.p_W_joint[j];
    if (!(camera.depth(a) > 0.0) || !(camera.depth(b) > 0.0)) continue;
    sum += (camera.project(a) - camera.project(b)).norm();
    ++n;
  }
  return n == 0 ? 0.0 : sum / n;
}

double fingertip_error_m(const hand::HandPoints& fitted, const hand::HandPoints& truth) {
  double sum = 0;
  for (int i = 0; i < hand::kFingertipCount; ++i) {
    sum += (fitted.p_W_fingertip[i] - truth.p_W_fingertip[i]).norm();
  }
  return sum / hand::kFingertipCount;
}

Vec3 palm_rotation_error_rad(const hand::HandParams& fitted, const hand::HandParams& truth,
                             hand::Side side) {
  const Eigen::AngleAxisd aa(hand::hand_pose(truth).R.conjugate() * hand::hand_pose(fitted).R);
  Vec3 w = aa.angle() * aa.axis();
  // The left hand's body is mirrored in x (hand_pose): a rotation vector, a pseudovector, maps
  // under that mirror M as w → det(M) M w = (w_x, −w_y, −w_z).
  if (side == hand::Side::kLeft) w = Vec3(w.x(), -w.y(), -w.z());
  return w;
}

}  // namespace spidar::registration
