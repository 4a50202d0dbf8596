#pragma once
/// Camera intrinsics from chessboard images (OpenCV findChessboardCorners → cornerSubPix →
/// calibrateCamera).
///
/// Board frame B: corner (i, j) (column i of `cols`, row j of `rows` inner corners, in the order
/// OpenCV reports them) sits at (i·square, j·square, 0) [m].
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::vision {

struct ChessboardPattern {
  int cols = 9;          ///< inner corners per row
  int rows = 6;          ///< inner corners per column
  double square = 0.025;  ///< side of one square [m]

  /// Corner positions in the board frame [m], OpenCV's order.
  std::vector<Vec3> corners_B() const;
};

/// Parses "9x6" (inner corners, cols x rows). Error says what was expected.
Result<ChessboardPattern> parse_pattern(const std::string& text, double square);

/// The pattern's inner corners in an image [px], refined to sub-pixel accuracy, or nullopt if
/// the board is not found. Accepts 8-bit grey or BGR images.
std::optional<std::vector<Vec2>> find_chessboard_corners(const cv::Mat& image,
                                                         const ChessboardPattern& pattern);

struct IntrinsicsOptions {
  bool fix_k3 = true;            ///< k3 = 0 (usual for ordinary lenses; avoids over-fitting)
  bool zero_tangential = false;  ///< p1 = p2 = 0
  bool no_distortion = false;    ///< all coefficients 0
};

struct IntrinsicsCalibration {
  Intrinsics intrinsics;
  double rms_px = 0;                 ///< OpenCV's overall RMS reprojection error [px]
  std::vector<double> view_rms_px;   ///< per view [px]
  std::vector<Pose> X_CB;            ///< board pose in each view (board → camera)
};

/// Runs cv::calibrateCamera on the corners of ≥ 3 views of one image size.
Result<IntrinsicsCalibration> calibrate_intrinsics(
    const std::vector<std::vector<Vec2>>& corners_per_view, const ChessboardPattern& pattern,
    int width, int height, const IntrinsicsOptions& options = {});

struct ChessboardFolderResult {
  IntrinsicsCalibration calibration;
  std::vector<std::string> used;      ///< images where the board was found
  std::vector<std::string> rejected;  ///< images where it was not
};

/// Image files (.png .jpg .jpeg .bmp .tif .tiff .pgm .ppm, any case) in a folder, sorted by name.
Result<std::vector<std::string>> list_images(const std::string& dir);

/// Finds the board in every image of `dir` and calibrates. Errors name the folder or image
/// (unreadable, size differs from the first image, fewer than 3 boards found).
Result<ChessboardFolderResult> calibrate_chessboard_folder(const std::string& dir,
                                                           const ChessboardPattern& pattern,
                                                           const IntrinsicsOptions& options = {});

}  // namespace spidar::vision
