#pragma once
/// Camera extrinsics from four or more markers at known world positions seen at known pixels
/// (Perspective-n-Point), with the reprojection error.
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision {

struct PnpResult {
  Pose X_CW;                         ///< world → camera
  double rms_px = 0;                 ///< RMS reprojection error over the markers [px]
  double max_px = 0;                 ///< largest reprojection error [px]
  std::vector<double> residuals_px;  ///< per marker, in input order [px]
};

/// Solves PnP with OpenCV (SQPnP for a global start, then Levenberg–Marquardt refinement),
/// through `intrinsics` (distortion included). Needs ≥ 4 markers, not all on one line, with
/// finite coordinates, all in front of the solved camera. Errors say which input is bad.
Result<PnpResult> solve_pnp(const Intrinsics& intrinsics, const std::vector<Vec3>& p_W,
                            const std::vector<Vec2>& uv);

/// Reprojection errors [px] of markers through a camera (per marker, input order).
std::vector<double> reprojection_errors(const Camera& camera, const std::vector<Vec3>& p_W,
                                        const std::vector<Vec2>& uv);

}  // namespace spidar::vision
