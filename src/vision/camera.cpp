#include "spidar/vision/camera.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "spidar/core/units.hpp"

namespace spidar::vision {

Mat3 Intrinsics::K() const {
  Mat3 K;
  K << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return K;
}

Status validate_intrinsics(const Intrinsics& in) {
  auto bad = [](const std::string& what) { return Status(Error{what}); };
  if (in.width < 16 || in.height < 16 || in.width > 16384 || in.height > 16384) {
    return bad("image size: expected 16..16384 px per side, got " + std::to_string(in.width) +
               "x" + std::to_string(in.height));
  }
  for (const auto& [name, f] : {std::pair{"fx", in.fx}, std::pair{"fy", in.fy}}) {
    if (!std::isfinite(f) || f <= 1.0 || f > 1e6) {
      return bad(std::string(name) + ": expected a focal length in (1, 1e6] px, got " +
                 std::to_string(f));
    }
  }
  if (!std::isfinite(in.cx) || in.cx < -0.5 || in.cx > in.width - 0.5) {
    return bad("cx: expected a principal point inside the image [-0.5, " +
               std::to_string(in.width - 0.5) + "] px, got " + std::to_string(in.cx));
  }
  if (!std::isfinite(in.cy) || in.cy < -0.5 || in.cy > in.height - 0.5) {
    return bad("cy: expected a principal point inside the image [-0.5, " +
               std::to_string(in.height - 0.5) + "] px, got " + std::to_string(in.cy));
  }
  const auto& d = in.distortion;
  for (double c : {d.k1, d.k2, d.p1, d.p2, d.k3}) {
    if (!std::isfinite(c) || std::abs(c) > 100.0) {
      return bad("distortion: expected finite coefficients of magnitude <= 100, got " +
                 std::to_string(c));
    }
  }
  return Ok{};
}

Camera::Camera(const Intrinsics& intrinsics, const Pose& X_CW) : intrinsics_(intrinsics) {
  set_X_CW(X_CW);
}

void Camera::set_X_CW(const Pose& X_CW) {
  X_CW_ = {X_CW.R.normalized(), X_CW.p};
  R_CW_ = X_CW_.R.toRotationMatrix();
}

Vec2 Camera::distort(const Vec2& xy, Eigen::Matrix2d* J) const {
  const auto& d = intrinsics_.distortion;
  const double x = xy.x(), y = xy.y();
  const double x2 = x * x, y2 = y * y, xy_ = x * y, r2 = x2 + y2;
  const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const Vec2 out(x * radial + 2.0 * d.p1 * xy_ + d.p2 * (r2 + 2.0 * x2),
                 y * radial + d.p1 * (r2 + 2.0 * y2) + 2.0 * d.p2 * xy_);
  if (J) {
    // ∂radial/∂(r²)
    const double dr = d.k1 + r2 * (2.0 * d.k2 + 3.0 * d.k3 * r2);
    const double cross = 2.0 * xy_ * dr + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    (*J)(0, 0) = radial + 2.0 * x2 * dr + 2.0 * d.p1 * y + 6.0 * d.p2 * x;
    (*J)(0, 1) = cross;
    (*J)(1, 0) = cross;
    (*J)(1, 1) = radial + 2.0 * y2 * dr + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  }
  return out;
}

Vec2 Camera::project_camera(const Vec3& p_C) const {
  const double z = std::max(p_C.z(), kMinDepth);
  const Vec2 xd = distort(Vec2(p_C.x() / z, p_C.y() / z), nullptr);
  return {intrinsics_.fx * xd.x() + intrinsics_.cx, intrinsics_.fy * xd.y() + intrinsics_.cy};
}

Vec2 Camera::project(const Vec3& p_W) const { return project_camera(to_camera(p_W)); }

Vec2 Camera::project(const Vec3& p_W, ProjectionJacobian* J) const {
  if (!J) return project(p_W);
  const Vec3 p_C = to_camera(p_W);
  const double z = std::max(p_C.z(), kMinDepth);
  const double inv_z = 1.0 / z;
  const Vec2 xy(p_C.x() * inv_z, p_C.y() * inv_z);
  Eigen::Matrix2d J_dist;
  const Vec2 xd = distort(xy, &J_dist);
  // ∂(x, y)/∂p_C
  Eigen::Matrix<double, 2, 3> J_norm;
  J_norm << inv_z, 0.0, -xy.x() * inv_z, 0.0, inv_z, -xy.y() * inv_z;
  if (p_C.z() < kMinDepth) J_norm.col(2).setZero();  // depth clamped: constant in z
  Eigen::Matrix2d F;
  F << intrinsics_.fx, 0.0, 0.0, intrinsics_.fy;
  *J = F * J_dist * J_norm * R_CW_;
  return {intrinsics_.fx * xd.x() + intrinsics_.cx, intrinsics_.fy * xd.y() + intrinsics_.cy};
}

ProjectionJacobian Camera::projection_jacobian(const Vec3& p_W) const {
  ProjectionJacobian J;
  project(p_W, &J);
  return J;
}

Vec2 Camera::undistort(const Vec2& uv) const {
  const Vec2 target((uv.x() - intrinsics_.cx) / intrinsics_.fx,
                    (uv.y() - intrinsics_.cy) / intrinsics_.fy);
  if (intrinsics_.distortion.is_zero()) return target;
  Vec2 xy = target;
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix2d J;
    const Vec2 r = distort(xy, &J) - target;
    if (r.squaredNorm() < 1e-28) break;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) break;  // distortion folds over here: keep the best so far
    const Vec2 step = J.inverse() * r;
    if (!step.allFinite()) break;
    xy -= step;
  }
  return xy;
}

Vec3 Camera::unproject_camera(const Vec2& uv, double depth) const {
  const Vec2 xy = undistort(uv);
  return {xy.x() * depth, xy.y() * depth, depth};
}

Vec3 Camera::unproject(const Vec2& uv, double depth) const {
  return R_CW_.transpose() * (unproject_camera(uv, depth) - X_CW_.p);
}

Vec3 Camera::ray_direction_W(const Vec2& uv) const {
  const Vec2 xy = undistort(uv);
  return R_CW_.transpose() * Vec3(xy.x(), xy.y(), 1.0).normalized();
}

Pose look_at(const Vec3& p_W_camera, const Vec3& p_W_target, const Vec3& up_W) {
  const Vec3 z = (p_W_target - p_W_camera).normalized();
  Vec3 x = z.cross(up_W);  // image right: forward × up
  if (x.norm() < 1e-9) x = z.cross(Vec3::UnitY());
  x.normalize();
  const Vec3 y = z.cross(x);  // image down
  Mat3 R_WC;
  R_WC.col(0) = x;
  R_WC.col(1) = y;
  R_WC.col(2) = z;
  const Pose X_WC{Quat(R_WC), p_W_camera};
  return X_WC.inverse();
}

Camera default_rig_camera() {
  // 50° below horizontal, optical axis through the frame centre, top of the frame at z = 0.30 m.
  const double pitch = units::deg_to_rad(50.0);
  const double height = 0.30;
  const Vec3 p_W_camera(0.0, -height / std::tan(pitch), height);
  return Camera(Intrinsics{}, look_at(p_W_camera, Vec3::Zero()));
}

}  // namespace spidar::vision
