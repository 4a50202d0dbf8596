#pragma once
/// The paper's camera calibration (eqs 15–20): the extrinsics from three markers.
///
/// Inputs: three markers m1, m2, m3, each with
///   - its position in the world p_W_i [m] (known: placed at surveyed spots on the frame, or
///     touched with a fingertip cap and read from the strings), and
///   - its position in camera coordinates p_C_i [m] (measured: e.g. the marker's pixel plus its
///     depth along the optical axis, `Camera::unproject_camera(uv, depth)`, or a stereo/range
///     measurement).
/// The markers must not be collinear; m1 is the anchor.
///
/// The paper builds an orthonormal triad from the three points,
///   x = V2 − V1,  y = (V3 − V1) − (x·(V3 − V1))/(x·x) · x,  z = x × y,  normalised,
/// and reads c = M w with M = [R T; 0 1], R = [x' y' z'], T from marker m1. Read literally that
/// assumes m1 at the world origin, m2 on the world x axis and m3 in the world xy plane. Here the
/// same triad is built in both frames (F_W from p_W_i, F_C from p_C_i), so the markers may sit
/// anywhere:  R_CW = R_CF · R_WFᵀ,  T = p_C_1 − R_CW · p_W_1.  With the paper's placement R_WF = I
/// and p_W_1 = 0, which gives its R = [x' y' z'], T = V1 exactly.
#include <array>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"

namespace spidar::vision {

struct MarkerPair {
  Vec3 p_W;  ///< marker position in the world [m]
  Vec3 p_C;  ///< the same marker measured in camera coordinates [m]
};

struct ThreeMarkerResult {
  Pose X_CW;            ///< world → camera
  double rms_m = 0;     ///< RMS of ‖X_CW·p_W_i − p_C_i‖ over the three markers [m]
  double max_m = 0;     ///< the largest of those [m]
  double scale_mismatch = 0;  ///< max relative difference of marker distances, world vs camera
};

/// The paper's three-marker extrinsics. Errors: non-finite input, markers closer than 1 cm to
/// each other or (nearly) collinear (triangle height below 1 % of its longest side), in
/// either frame.
Result<ThreeMarkerResult> three_marker_extrinsics(const std::array<MarkerPair, 3>& markers);

}  // namespace spidar::vision
