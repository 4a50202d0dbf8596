#include "spidar/hand/forearm.hpp"

#include <cmath>
#include <numbers>

#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {

Vec3 forearm_direction(const Mat3& R_WH, const Vec3& p_W_wrist, const Vec3& p_W_elbow, double max_bend_rad) {
  const Vec3 axis = -R_WH.col(1);
  const Vec3 to_elbow = p_W_elbow - p_W_wrist;
  const double n = to_elbow.norm();
  if (!(n > 1e-9) || !to_elbow.allFinite()) return axis;
  if (!(max_bend_rad >= 0 && max_bend_rad <= std::numbers::pi)) return axis;
  const Vec3 d = to_elbow / n;
  const double angle = std::atan2(axis.cross(d).norm(), axis.dot(d));
  if (angle <= max_bend_rad) return d;
  // Turn the hand's axis toward d by the limit, in the plane of the two.
  Vec3 normal = axis.cross(d);
  if (normal.norm() < 1e-12) {  // d opposite the axis: any plane will do; flex about x_H
    normal = R_WH.col(0);
  }
  return Eigen::AngleAxisd(max_bend_rad, normal.normalized()) * axis;
}

Mat3 wrist_bend(const Mat3& R_WH, const Vec3& toward_elbow_W) {
  return Quat::FromTwoVectors(-R_WH.col(1), toward_elbow_W).toRotationMatrix();
}

Pose forearm_pose(const Pose& X_WH, const Vec3& toward_elbow_W) {
  const Mat3 R = X_WH.R.toRotationMatrix();
  return Pose{Quat(wrist_bend(R, toward_elbow_W) * R).normalized(), X_WH.p};
}

Vec3 elbow_in_line(const HandParams& q, double forearm_length_m) {
  return q.p_W_wrist() - forearm_length_m * rotation_from_vector(q.r_W_hand()).col(1);
}

}  // namespace spidar::hand
