#pragma once
/// Rigid transforms with Drake-style frame naming: `X_AB` is the pose of frame B in frame A,
/// so `p_AQ = X_AB * p_BQ` and `X_AC = X_AB * X_BC`.
#include "spidar/core/types.hpp"

namespace spidar {

struct Pose {
  Quat R = Quat::Identity();  ///< rotation of B in A (unit quaternion)
  Vec3 p = Vec3::Zero();      ///< position of B's origin in A [m]

  static Pose Identity() { return {}; }
  static Pose FromRotationVector(const Vec3& rotvec_rad, const Vec3& p_AB);

  /// Transforms a point given in B into A.
  Vec3 operator*(const Vec3& p_BQ) const { return R * p_BQ + p; }
  /// Composition: (X_AB * X_BC) = X_AC.
  Pose operator*(const Pose& X_BC) const { return {R * X_BC.R, R * X_BC.p + p}; }
  /// X_BA from X_AB.
  Pose inverse() const {
    const Quat Rinv = R.conjugate();
    return {Rinv, -(Rinv * p)};
  }
  /// 4×4 homogeneous matrix [R p; 0 1].
  Mat4 matrix() const;
};

}  // namespace spidar
