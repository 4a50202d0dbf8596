#pragma once
/// A markers file for extrinsic calibration, and the extrinsics it gives.
///
///   markers:                        # world positions [m] (rig frame)
///     - name: m1                    # optional
///       world: [-0.2, 0.1, 0.0]
///       pixel: [102.4, 311.0]       # where the fixed camera sees it [px]  → PnP (≥ 4 markers)
///     # or, the paper's method (exactly 3 markers):
///     - name: m1
///       world: [0, 0, 0]
///       camera: [0.01, 0.02, 0.39]  # measured in camera coordinates [m]   → three-marker
///
/// Every marker must carry the same kind of measurement (all `pixel` or all `camera`).
#include <optional>
#include <string>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/core/pose.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision {

struct Marker {
  std::string name;
  Vec3 p_W = Vec3::Zero();
  std::optional<Vec2> uv;   ///< pixel [px]
  std::optional<Vec3> p_C;  ///< camera coordinates [m]
};

struct MarkerSet {
  std::vector<Marker> markers;
  bool by_pixel = true;  ///< true: all have `pixel`; false: all have `camera`
  std::string source;
};

/// Throws core::ConfigError naming file:line: key.
MarkerSet parse_markers(const core::ConfigNode& root);
MarkerSet load_markers(const std::string& path);

struct ExtrinsicsResult {
  Pose X_CW;
  std::string method;               ///< "pnp" or "three-marker"
  std::optional<double> rms_px;     ///< PnP reprojection RMS [px]
  std::optional<double> max_px;
  std::optional<double> rms_m;      ///< three-marker residual RMS [m]
};

/// PnP (pixels, ≥ 4 markers) or the paper's three-marker method (camera coordinates, 3).
Result<ExtrinsicsResult> calibrate_extrinsics(const Intrinsics& intrinsics, const MarkerSet& set);

}  // namespace spidar::vision
