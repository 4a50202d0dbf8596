#pragma once
/// The string calibration procedure on a device (`spidar-mr calibrate-strings`): finger by
/// finger, the user brings the fingertip cap to the pole tip (the paper's pole calibration) or to
/// each point of a multi-point jig and holds still; once its strings have held still
/// (strings::StabilityCheck on the servo cycle's unwrapped counts, device::UnwrappedCounts) the
/// mean counts are sampled, and the finger's channels are computed (strings::pole_calibrate or
/// strings::fit_multipoint). Writing them back is the caller's (strings/device_config_write.hpp).
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/stability_check.hpp"

namespace spidar::device {

struct StringCalibrationParams {
  std::vector<int> fingers;            ///< config indices, in the order to calibrate
  int jig = 0;                         ///< 0: pole; N ≥ 2: an N×N×N jig grid
  double jig_spacing_m = 0.04;         ///< jig point spacing [m]
  strings::StabilityParams stability;  ///< when a fingertip counts as held still
  double timeout_s = 30;               ///< give up on a point after this long [s]
};

/// The procedure's clock and pacing: `now_s` gives the time [s] (simulated or real), `pace` is
/// called after each read and write (a real device: sleep a period; a simulated one: advance).
struct CalibrationClock {
  std::function<double()> now_s;
  std::function<void()> pace;
};

/// What the procedure reports as it goes: a line of guidance or progress for the user.
using CalibrationProgress = std::function<void(const std::string& line)>;

/// The simulated user during calibration: the active finger moves from its rest point to the
/// target (smoothly, in `approach_s`) and holds there; the others hover, moving, at their rest
/// points (so they never pass the stability check). Call `activate` when the step changes.
class CalibrationUser final : public FingertipSource {
 public:
  explicit CalibrationUser(const strings::DeviceConfig& config, double approach_s = 0.6);
  /// Called at each new target (the procedure's `on_target`): time t [s].
  void activate(int finger, const Vec3& p_W_target, double t_s);
  void goals(double t_s, std::span<Vec3> p_W_goal) override;

 private:
  std::vector<Vec3> rest_;
  ScriptedFingertips::Script hover_;
  double approach_s_;
  int finger_ = -1;
  Vec3 from_ = Vec3::Zero(), target_ = Vec3::Zero();
  double t_active_ = 0;
};

/// One finger's result.
struct FingerCalibration {
  int finger = -1;                                ///< config index
  std::vector<strings::EncoderChannel> channels;  ///< the new channels, one per string
  /// Multi-point: the fit's RMS length residual per string [m]; empty for the pole.
  std::vector<double> residual_rms_m;
  /// Pole: distance of the sampled fingertip from the pole by the old and new channels [m].
  std::optional<double> pole_error_before_m, pole_error_after_m;
};

/// The targets of a calibration: the pole tip (`config.p_W_centre`) or the jig grid around it.
std::vector<Vec3> calibration_targets(const strings::DeviceConfig& config,
                                      const StringCalibrationParams& params);

/// Runs the procedure on an open device (commands at their minimum, strings taut), finger by
/// finger. `on_target(finger, target, t_s)` is called as each target is announced (to move a
/// simulated user; may be empty). Errors name the finger and what went wrong: the device read
/// failed, the fingertip did not hold still near its target within the timeout, the fit failed.
Result<std::vector<FingerCalibration>> calibrate_strings(
    Device& device, const strings::DeviceConfig& config, const StringCalibrationParams& params,
    const CalibrationClock& clock, const CalibrationProgress& progress,
    const std::function<void(int finger, const Vec3& p_W_target, double t_s)>& on_target = {});

}  // namespace spidar::device
