#include "spidar/render/overlay.hpp"

#include <cmath>
#include <optional>
#include <opencv2/imgproc.hpp>

namespace spidar::render {
namespace {

// OpenCV's drawing takes integer pixels with `shift` fractional bits.
constexpr int kShift = 4;
constexpr double kScale = 1 << kShift;

std::optional<cv::Point> to_pixel(const vision::Camera& camera, const Vec3& p_W) {
  if (!p_W.allFinite() || camera.depth(p_W) <= 1e-3) return std::nullopt;
  const Vec2 uv = camera.project(p_W);
  if (!uv.allFinite() || uv.cwiseAbs().maxCoeff() > 1e5) return std::nullopt;
  return cv::Point(static_cast<int>(std::lround(uv.x() * kScale)),
                   static_cast<int>(std::lround(uv.y() * kScale)));
}

cv::Scalar scalar(const Bgr& c) { return {double(c[0]), double(c[1]), double(c[2])}; }

void line(cv::Mat& img, const vision::Camera& cam, const Vec3& a, const Vec3& b, const Bgr& c,
          int thickness) {
  const auto pa = to_pixel(cam, a), pb = to_pixel(cam, b);
  if (pa && pb) cv::line(img, *pa, *pb, scalar(c), thickness, cv::LINE_AA, kShift);
}

}  // namespace

void draw_hand_wireframe(cv::Mat& bgr, const vision::Camera& camera,
                         const hand::HandRenderShapes& shapes, const Bgr& colour) {
  for (const auto& c : shapes.capsules) {
    line(bgr, camera, c.p_W_a, c.p_W_b, colour, 1);
    for (const Vec3& p : {c.p_W_a, c.p_W_b})
      if (auto px = to_pixel(camera, p)) cv::circle(bgr, *px, 2 << kShift, scalar(colour), 1, cv::LINE_AA, kShift);
  }
  for (const auto& box : shapes.boxes) {
    for (int i = 0; i < 8; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        if (i & (1 << axis)) continue;  // each edge once: from the corner with that bit clear
        const int j = i | (1 << axis);
        auto corner = [&](int k) {
          const Vec3 s((k & 1) ? 1 : -1, (k & 2) ? 1 : -1, (k & 4) ? 1 : -1);
          return box.X_WB * Vec3(s.cwiseProduct(box.half_extents));
        };
        line(bgr, camera, corner(i), corner(j), colour, 1);
      }
    }
  }
}

void draw_force_arrows(cv::Mat& bgr, const vision::Camera& camera, std::span<const Vec3> p_W,
                       std::span<const Vec3> f_W, double metres_per_newton, const Bgr& colour) {
  const std::size_t n = std::min(p_W.size(), f_W.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!f_W[i].allFinite() || f_W[i].norm() * metres_per_newton < 1e-4) continue;
    const auto a = to_pixel(camera, p_W[i]), b = to_pixel(camera, p_W[i] + metres_per_newton * f_W[i]);
    if (a && b) cv::arrowedLine(bgr, *a, *b, scalar(colour), 2, cv::LINE_AA, kShift, 0.25);
  }
}

void draw_strings(cv::Mat& bgr, const vision::Camera& camera, std::span<const Vec3> p_W_a,
                  std::span<const Vec3> p_W_b, const Bgr& colour) {
  const std::size_t n = std::min(p_W_a.size(), p_W_b.size());
  for (std::size_t i = 0; i < n; ++i) line(bgr, camera, p_W_a[i], p_W_b[i], colour, 1);
}

}  // namespace spidar::render
