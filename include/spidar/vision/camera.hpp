#pragma once
/// The pinhole camera with OpenCV's lens distortion, in OpenCV's convention: camera frame C has
/// x right, y down, z forward (along the optical axis); pixel (0, 0) is the *centre* of the
/// top-left pixel, u grows to the right and v downwards.
///
/// A world point p_W maps to pixels by
///   p_C = X_CW * p_W,  x = p_C.x / p_C.z,  y = p_C.y / p_C.z,  r² = x² + y²,
///   radial = 1 + k1 r² + k2 r⁴ + k3 r⁶,
///   x' = x·radial + 2 p1 x y + p2 (r² + 2x²),   y' = y·radial + p1 (r² + 2y²) + 2 p2 x y,
///   u = fx x' + cx,  v = fy y' + cy,
/// which is exactly cv::projectPoints with distortion (k1, k2, p1, p2, k3).
#include <Eigen/Core>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"

namespace spidar::vision {

/// OpenCV's 5-coefficient distortion (k1, k2, p1, p2, k3), dimensionless.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
};

/// Intrinsics: focal lengths and principal point [px], distortion, image size [px].
struct Intrinsics {
  double fx = 554.256;  ///< [px]; 554.256 = 320 / tan(30°): 60° horizontal field of view at 640 px
  double fy = 554.256;  ///< [px]
  double cx = 319.5;    ///< [px], image centre of a 640-px-wide image in the pixel-centre convention
  double cy = 239.5;    ///< [px]
  Distortion distortion;
  int width = 640;   ///< [px]
  int height = 480;  ///< [px]

  /// Camera matrix K = [fx 0 cx; 0 fy cy; 0 0 1].
  Mat3 K() const;
};

/// Checks focal lengths, principal point, image size and distortion for sanity; the error says
/// which value is wrong and what was expected.
Status validate_intrinsics(const Intrinsics& intrinsics);

/// ∂(u, v)/∂p_W: 2×3, [px/m].
using ProjectionJacobian = Eigen::Matrix<double, 2, 3>;

class Camera {
 public:
  /// Points closer to the camera plane than this [m] are treated as lying at this depth, so that
  /// projecting a point behind the camera gives large but finite pixels (never NaN).
  static constexpr double kMinDepth = 1e-6;

  Camera() = default;
  /// `X_CW`: pose of the world frame in the camera frame (maps world points to camera points).
  Camera(const Intrinsics& intrinsics, const Pose& X_CW);

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Pose& X_CW() const { return X_CW_; }
  /// The camera's pose in the world: its centre X_WC.p and axes X_WC.R (columns: x, y, z of C).
  Pose X_WC() const { return X_CW_.inverse(); }
  void set_intrinsics(const Intrinsics& intrinsics) { intrinsics_ = intrinsics; }
  void set_X_CW(const Pose& X_CW);

  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }

  /// Point in camera coordinates [m].
  Vec3 to_camera(const Vec3& p_W) const { return R_CW_ * p_W + X_CW_.p; }
  /// Depth of a world point along the optical axis [m] (negative: behind the camera).
  double depth(const Vec3& p_W) const { return to_camera(p_W).z(); }

  /// Pixel of a world point [px], with distortion.
  Vec2 project(const Vec3& p_W) const;
  /// Pixel of a point given in camera coordinates [px].
  Vec2 project_camera(const Vec3& p_C) const;
  /// ∂(u, v)/∂p_W at p_W [px/m] (exact, including distortion).
  ProjectionJacobian projection_jacobian(const Vec3& p_W) const;
  /// Both at once (shares the work).
  Vec2 project(const Vec3& p_W, ProjectionJacobian* J) const;

  /// Normalised undistorted image coordinates (x, y) = (X/Z, Y/Z) of a pixel: removes the
  /// distortion by Newton iterations (converges to ~1e-12 within the image for sane lenses).
  Vec2 undistort(const Vec2& uv) const;
  /// Point in camera coordinates at depth `depth` [m] (along z_C) that projects to pixel uv.
  Vec3 unproject_camera(const Vec2& uv, double depth) const;
  /// World point at depth `depth` [m] (along z_C) that projects to pixel uv.
  Vec3 unproject(const Vec2& uv, double depth) const;
  /// Unit direction in the world of the ray through pixel uv (from the camera centre).
  Vec3 ray_direction_W(const Vec2& uv) const;

  /// True if uv lies inside the image (pixel centres 0..width-1, with half a pixel either side).
  bool in_image(const Vec2& uv) const {
    return uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < width() - 0.5 && uv.y() < height() - 0.5;
  }

 private:
  /// Distortion of normalised coordinates; if J is given, ∂(x', y')/∂(x, y).
  Vec2 distort(const Vec2& xy, Eigen::Matrix2d* J) const;

  Intrinsics intrinsics_;
  Pose X_CW_;
  Mat3 R_CW_ = Mat3::Identity();
};

/// The default rig camera (configs/camera.yaml ships the same): 640×480, 60° horizontal field of
/// view, no distortion, at the top of the SPIDAR-8 frame on its centre line, on the user's side
/// (world (0, −0.2517, 0.30) m), looking away from the user and down 50° from the horizontal, so
/// that its optical axis meets the table-level plane z = 0 at the frame centre.
Camera default_rig_camera();

/// Camera pose from where it is and where it looks: X_CW for a camera at p_W_camera whose
/// optical axis points at p_W_target, with image "up" as close as possible to world +z.
Pose look_at(const Vec3& p_W_camera, const Vec3& p_W_target, const Vec3& up_W = Vec3::UnitZ());

}  // namespace spidar::vision
