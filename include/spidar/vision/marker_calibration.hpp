#pragma once
/// The camera's extrinsic calibration from markers whose world positions are measured one by one
/// and then clicked in the camera image (the live session's "Camera calibration" step, where the
/// user touches each marker with a fingertip cap; `calibrate-camera --markers FILE` does the same
/// from a file, which `markers_yaml()` writes).
///
/// For each marker: its world position p_W [m] comes in (`touched`: from the strings, once the
/// fingertip held still), the marker waits for its click, then the pixel uv [px] is set. Two
/// solvers, by the number of markers:
///   - three markers: the paper's method (eqs 15–20) needs each marker in camera coordinates,
///     p_C = range · (unit ray through uv), with `range_m` the measured distance from the camera
///     centre to the marker [m] (a tape measure; it defaults to the present calibration's range,
///     which gives back the present extrinsics up to the clicks' error, so measure it);
///   - four or more: PnP from the pixels alone (ranges unused).
/// The intrinsics are kept (they come from `calibrate-camera --images`).
#include <optional>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/markers.hpp"

namespace spidar::vision {

struct CapturedMarker {
  std::string name;
  Vec3 p_W = Vec3::Zero();   ///< measured world position [m]
  std::optional<Vec2> uv;    ///< clicked in the camera image [px]
  double range_m = 0;        ///< camera centre to marker [m] (three-marker method)
  double held_spread_m = 0;  ///< how still the measuring fingertip was while sampled [m]
};

class MarkerCalibration {
 public:
  /// `present`: the camera now in use (its intrinsics are kept; its pose gives default ranges).
  /// `measured_with` names what measures the world positions (e.g. the finger), for the file.
  MarkerCalibration(const Camera& present, std::string measured_with);

  /// The next marker's measured world position [m] and how still it was held [m]: it becomes
  /// the marker waiting for its click (replacing one that waited). Errors if p_W is not finite.
  Status touched(const Vec3& p_W, double held_spread_m);
  /// The marker waiting for its click (measured, no pixel yet), if any.
  const CapturedMarker* pending() const { return pending_ ? &*pending_ : nullptr; }
  /// Forgets the waiting marker (a new touch begins).
  void drop_pending() { pending_.reset(); }
  /// The click on the pending marker [px]; its range defaults to the present camera's. Errors if
  /// no marker is pending or the pixel is outside the image.
  Status set_pixel(const Vec2& uv);
  /// The measured range of marker i [m] (> 0.05, finite).
  Status set_range(std::size_t i, double range_m);
  /// Adds a complete marker directly (a marker typed in, or a test).
  void add(const CapturedMarker& m) { markers_.push_back(m); }
  void remove_last();
  const std::vector<CapturedMarker>& markers() const { return markers_; }

  /// The marker set for calibrate_extrinsics: camera coordinates for exactly three markers (the
  /// paper's method), pixels for four or more (PnP). Errors below three.
  Result<MarkerSet> marker_set() const;
  /// Solves the extrinsics from the markers so far; the camera with the present intrinsics and
  /// the new pose, and the residuals. Errors name what is missing or degenerate.
  struct Solution {
    Camera camera;
    ExtrinsicsResult extrinsics;
    double moved_m = 0;     ///< camera centre moved from the present calibration [m]
    double turned_deg = 0;  ///< camera axes turned from the present calibration [deg]
  };
  Result<Solution> solve() const;

  /// The markers as a markers file (vision/markers.hpp format) for `calibrate-camera --markers`.
  std::string markers_yaml() const;

 private:
  Camera present_;
  std::string measured_with_;
  std::optional<CapturedMarker> pending_;
  std::vector<CapturedMarker> markers_;
};

}  // namespace spidar::vision
