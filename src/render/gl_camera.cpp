#include "spidar/render/gl_camera.hpp"

#include <cmath>
#include <string>

namespace spidar::render {

Status validate(const DepthRange& range) {
  if (!(std::isfinite(range.near_m) && std::isfinite(range.far_m) && range.near_m > 0 &&
        range.far_m > range.near_m))
    return Error{"depth range: expected 0 < near < far [m], got near " +
                 std::to_string(range.near_m) + ", far " + std::to_string(range.far_m)};
  return Ok{};
}

Mat4 gl_projection(const vision::Intrinsics& K, const DepthRange& range) {
  const double W = K.width, H = K.height, n = range.near_m, f = range.far_m;
  Mat4 P = Mat4::Zero();
  P(0, 0) = 2.0 * K.fx / W;
  P(0, 2) = 2.0 * (K.cx + 0.5) / W - 1.0;
  P(1, 1) = 2.0 * K.fy / H;
  P(1, 2) = 2.0 * (K.cy + 0.5) / H - 1.0;
  P(2, 2) = (f + n) / (f - n);
  P(2, 3) = -2.0 * f * n / (f - n);
  P(3, 2) = 1.0;
  return P;
}

Mat4 gl_view(const Pose& X_CW) { return X_CW.matrix(); }

Mat4 gl_view_projection(const vision::Camera& camera, const DepthRange& range) {
  return gl_projection(camera.intrinsics(), range) * gl_view(camera.X_CW());
}

Vec3 gl_pixel_and_depth(const vision::Camera& camera, const DepthRange& range, const Vec3& p_W) {
  const Vec4 clip = gl_view_projection(camera, range) * p_W.homogeneous();
  const double W = camera.width(), H = camera.height();
  const double x_ndc = clip.x() / clip.w(), y_ndc = clip.y() / clip.w();
  // NDC → GL window coordinates → OpenCV pixels (window minus ½).
  const double u = (x_ndc + 1.0) * 0.5 * W - 0.5, v = (y_ndc + 1.0) * 0.5 * H - 0.5;
  return {u, v, clip.w()};
}

}  // namespace spidar::render
