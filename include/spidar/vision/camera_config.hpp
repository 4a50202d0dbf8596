#pragma once
/// configs/camera.yaml: a vision::Camera on disk, validated on load.
///
///   camera:
///     image_size: [640, 480]          # width, height [px]
///     fx: 554.256                     # focal lengths [px]
///     fy: 554.256
///     cx: 319.5                       # principal point [px]; (0, 0) = centre of the top-left pixel
///     cy: 239.5
///     distortion: [0, 0, 0, 0, 0]     # OpenCV k1, k2, p1, p2, k3 (optional, default zeros)
///     pose:                           # where the camera is in the world (X_WC)
///       position: [0, -0.2517, 0.30]  # camera centre in world [m]
///       rotation_vector: [...]        # R_WC as a rotation vector [rad]: columns = camera x, y, z
///       # or, instead of rotation_vector:
///       look_at: [0, 0, 0]            # a world point on the optical axis; image up ≈ world +z
///     calibration:                    # optional, informational; written by calibrate-camera
///       intrinsics_rms_px: 0.08
///       extrinsics_rms_px: 0.31
///
/// The world frame is the rig's: origin at the SPIDAR-8 frame centre, z up, x to the user's
/// right, y away from the user. Errors name file:line: key, e.g.
/// `camera.yaml:5: camera.fx: expected a focal length in (1, 1e6] px, got -3`.
#include <optional>
#include <string>

#include "spidar/core/config.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision {

/// Calibration figures kept with a camera file (not needed to use the camera).
struct CalibrationNotes {
  std::optional<double> intrinsics_rms_px;  ///< chessboard reprojection RMS [px]
  std::optional<double> extrinsics_rms_px;  ///< marker reprojection RMS [px] (PnP)
  std::optional<double> extrinsics_rms_m;   ///< marker residual RMS [m] (three-marker method)
  std::string method;                       ///< e.g. "chessboard + pnp"
};

struct CameraFile {
  Camera camera;
  CalibrationNotes calibration;
  std::string source;  ///< file it came from (empty when parsed from text)
};

/// Parses the `camera:` document. Throws core::ConfigError naming file:line: key.
CameraFile parse_camera_file(const core::ConfigNode& root);
/// Loads and validates a camera file.
CameraFile load_camera_file(const std::string& path);
/// YAML text of a camera file, with comments on units and frames (round-trips exactly).
std::string camera_file_yaml(const Camera& camera, const CalibrationNotes& notes = {});
/// Writes a camera file (creating missing parent folders). Error names the path.
Status save_camera_file(const std::string& path, const Camera& camera,
                        const CalibrationNotes& notes = {});

}  // namespace spidar::vision
