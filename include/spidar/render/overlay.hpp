#pragma once
/// 2-D overlays drawn onto a composite (OpenCV drawing, anti-aliased): the hand model as a
/// wireframe, fingertip forces as arrows, the strings as lines. Points behind the camera are
/// skipped; lines are clipped to the image by OpenCV.
#include <array>
#include <opencv2/core/mat.hpp>
#include <span>

#include "spidar/core/types.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::render {

using Bgr = std::array<std::uint8_t, 3>;

/// Each capsule's axis as a line with a dot at its joints; the palm box as its 12 edges.
void draw_hand_wireframe(cv::Mat& bgr, const vision::Camera& camera,
                         const hand::HandRenderShapes& shapes, const Bgr& colour = {80, 255, 80});

/// An arrow from p_W[i] along f_W[i] · metres_per_newton (e.g. 0.01 m/N: 1 N draws 1 cm).
void draw_force_arrows(cv::Mat& bgr, const vision::Camera& camera, std::span<const Vec3> p_W,
                       std::span<const Vec3> f_W, double metres_per_newton = 0.01,
                       const Bgr& colour = {0, 220, 255});

/// Lines from each fulcrum p_W_a[i] to its attachment p_W_b[i] (the strings).
void draw_strings(cv::Mat& bgr, const vision::Camera& camera, std::span<const Vec3> p_W_a,
                  std::span<const Vec3> p_W_b, const Bgr& colour = {230, 230, 230});

}  // namespace spidar::render
