#include "spidar/core/pose.hpp"

namespace spidar {

Pose Pose::FromRotationVector(const Vec3& rotvec_rad, const Vec3& p_AB) {
  const double angle = rotvec_rad.norm();
  Quat R = Quat::Identity();
  if (angle > 0.0) R = Quat(Eigen::AngleAxisd(angle, rotvec_rad / angle));
  return {R, p_AB};
}

Mat4 Pose::matrix() const {
  Mat4 M = Mat4::Identity();
  M.topLeftCorner<3, 3>() = R.toRotationMatrix();
  M.topRightCorner<3, 1>() = p;
  return M;
}

}  // namespace spidar
