#pragma once
/// The GUI's camera calibration step (window "Camera calibration"): the extrinsics from markers
/// touched with a fingertip cap (held still: strings::StabilityCheck on the unwrapped counts) and
/// clicked in the camera view (vision::MarkerCalibration), written back
/// to the session's camera file (previous version kept) and optionally as a markers file for
/// `calibrate-camera --markers`.
#include <imgui.h>

#include <memory>
#include <optional>
#include <string>

#include "spidar/session/live_session.hpp"
#include "spidar/device/unwrapped_counts.hpp"
#include "spidar/strings/stability_check.hpp"
#include "spidar/vision/marker_calibration.hpp"

namespace spidar::app {

class CameraCalibrationPanel {
 public:
  /// The panel's own window contents.
  void draw(session::LiveSession& s);
  /// Called right after the view's image was drawn: `image_min` is its top-left corner on the
  /// screen and `scale` screen pixels per camera pixel. Takes a click on the image as the pending
  /// marker's pixel and draws the markers (green: done, yellow: where the present calibration
  /// expects the pending one).
  void on_view(const session::LiveSession& s, const ImVec2& image_min, float scale);
  /// True while the panel waits for a click in the view.
  bool wants_click() const { return cal_ && cal_->pending(); }

 private:
  int finger_ = -1;
  std::unique_ptr<vision::MarkerCalibration> cal_;
  std::unique_ptr<strings::StabilityCheck> check_;  ///< while a marker is being touched
  std::unique_ptr<device::UnwrappedCounts> counts_;
  std::optional<vision::MarkerCalibration::Solution> solution_;
  std::string message_;
};

}  // namespace spidar::app
