#pragma once
/// The one place where a vision::Camera (OpenCV convention) becomes OpenGL's view and projection.
///
/// OpenCV camera frame C: x right, y down, z forward; pixel (0, 0) is the centre of the top-left
/// pixel, so pixel (u, v) covers [u − ½, u + ½] × [v − ½, v + ½]. GL's habit is an eye frame with
/// y up and z backward and w_clip = −z_eye. We skip that frame: the view matrix is X_CW itself
/// (world → C), and the projection puts w_clip = +z_C:
///
///   x_clip = (2 fx / W) x_C + (2 (cx + ½) / W − 1) z_C
///   y_clip = (2 fy / H) y_C + (2 (cy + ½) / H − 1) z_C
///   z_clip = (f + n)/(f − n) z_C − 2 f n / (f − n)          (z_ndc = −1 at z_C = n, +1 at f)
///   w_clip = z_C
///
/// so a point at pixel (u, v) lands at GL window coordinates (u + ½, v + ½): GL pixel centres sit
/// at half-integers, OpenCV's at integers, hence the ½. GL window row y_w = v means GL's "bottom"
/// row 0 is the image's top row: glReadPixels returns rows in image order (no flip on read-back),
/// and showing the image in a window needs one vertical flip (Renderer::present). That flip is a
/// mirror, so outward faces, counter-clockwise seen from outside in the world, are clockwise in
/// window coordinates: the renderer culls with glFrontFace(GL_CW).
///
/// Lens distortion is not rasterised: a camera with distortion renders as its pinhole (undistort
/// real frames with the same intrinsics before compositing them with a rendering).
#include <Eigen/Core>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::render {

/// Near and far clipping planes along the optical axis [m].
struct DepthRange {
  double near_m = 0.02;
  double far_m = 10.0;
};

/// Error unless 0 < near < far and both finite.
Status validate(const DepthRange& range);

/// Projection from the camera frame C (OpenCV axes) to GL clip space, as above.
Mat4 gl_projection(const vision::Intrinsics& intrinsics, const DepthRange& range);
/// View: world → camera frame C, i.e. X_CW as a 4×4 matrix.
Mat4 gl_view(const Pose& X_CW);
/// projection · view.
Mat4 gl_view_projection(const vision::Camera& camera, const DepthRange& range);

/// Where GL puts a world point: (u, v) in OpenCV pixels and z_C [m] along the optical axis,
/// computed through clip space and NDC (for tests of the matrices against Camera::project).
Vec3 gl_pixel_and_depth(const vision::Camera& camera, const DepthRange& range, const Vec3& p_W);

}  // namespace spidar::render
