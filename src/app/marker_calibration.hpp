#pragma once
/// The camera's extrinsic calibration in the live session, with the fingertip caps as markers
/// (the GUI's "Camera calibration" step; `calibrate-camera --markers FILE` does the same from a
/// file, which `markers_yaml()` writes).
///
/// For each marker the user touches a spot with one fingertip cap and holds still: its world
/// position p_W [m] is read from that finger's strings (StabilityCheck on its counts, then
/// solve_position on the mean counts). Then the user clicks the cap in the camera view: its pixel
/// uv [px]. Two solvers, by the number of markers:
///   - three markers: the paper's method (eqs 15–20) needs each marker in camera coordinates,
///     p_C = range · (unit ray through uv), with `range_m` the measured distance from the camera
///     centre to the marker [m] (a tape measure; it defaults to the present calibration's range,
///     which gives back the present extrinsics up to the clicks' error, so measure it);
///   - four or more: PnP from the pixels alone (ranges unused).
/// The intrinsics are kept (they come from `calibrate-camera --images`).
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/markers.hpp"
#include "string_calibration.hpp"

namespace spidar::app {

struct CapturedMarker {
  std::string name;
  Vec3 p_W = Vec3::Zero();      ///< from the strings [m], world
  std::optional<Vec2> uv;       ///< clicked in the camera image [px]
  double range_m = 0;           ///< camera centre to marker [m] (three-marker method)
  double held_spread_m = 0;     ///< how still the fingertip was while sampled [m]
};

class MarkerCalibration {
 public:
  /// `present`: the camera now in use (its intrinsics are kept; its pose gives default ranges).
  /// `finger`: the finger whose cap touches the markers.
  MarkerCalibration(const vision::Camera& present, const strings::FingerConfig& finger,
                    StabilityParams stability = {});

  /// Starts sampling a new marker: the fingertip must now hold still on it.
  void begin_touch();
  bool touching() const { return check_ != nullptr; }
  /// A reading of the finger's strings (config order) at time t [s] while touching. Once it has
  /// held still the marker's world position is taken and the marker waits for its pixel.
  void update(double t_s, std::span<const std::int64_t> finger_counts);
  const StabilityCheck* check() const { return check_.get(); }

  /// The marker waiting for its click (sampled, no pixel yet), if any.
  const CapturedMarker* pending() const { return pending_ ? &*pending_ : nullptr; }
  /// The click on the pending marker [px]; its range defaults to the present camera's. Errors if
  /// no marker is pending or the pixel is outside the image.
  Status set_pixel(const Vec2& uv);
  /// The measured range of marker i [m] (> 0.05, finite).
  Status set_range(std::size_t i, double range_m);
  /// Adds a complete marker directly (a marker typed in, or a test).
  void add(const CapturedMarker& m) { markers_.push_back(m); }
  void remove_last();
  const std::vector<CapturedMarker>& markers() const { return markers_; }

  /// The marker set for vision::calibrate_extrinsics: camera coordinates for exactly three
  /// markers (the paper's method), pixels for four or more (PnP). Errors below three.
  Result<vision::MarkerSet> marker_set() const;
  /// Solves the extrinsics from the markers so far; the camera with the present intrinsics and
  /// the new pose, and the residuals. Errors name what is missing or degenerate.
  struct Solution {
    vision::Camera camera;
    vision::ExtrinsicsResult extrinsics;
    double moved_m = 0;    ///< camera centre moved from the present calibration [m]
    double turned_deg = 0; ///< camera axes turned from the present calibration [deg]
  };
  Result<Solution> solve() const;

  /// The markers as a markers file (vision/markers.hpp format) for `calibrate-camera --markers`.
  std::string markers_yaml() const;

 private:
  vision::Camera present_;
  const strings::FingerConfig& finger_;
  StabilityParams stability_;
  std::unique_ptr<StabilityCheck> check_;
  std::optional<CapturedMarker> pending_;
  std::vector<CapturedMarker> markers_;
};

}  // namespace spidar::app
