#pragma once
/// The string calibration steps of `spidar-mr calibrate-strings`, apart from the CLI so tests can
/// drive them: a stability check on one finger's encoder counts (the fingertip must hold still
/// near its target for a moment before its sample is taken), the simulated user who brings each
/// fingertip to the pole or the jig points, and writing calibrated channels back into a device
/// config's YAML text (comments and layout kept).
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "spidar/device/device.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::app {

/// Finger `finger`'s counts (config order) out of a whole device reading.
std::vector<std::int64_t> finger_counts(const strings::DeviceConfig& config, int finger,
                                        const device::EncoderReading& reading);

/// Where the finger's calibration `channels` put its fingertip for these counts [m], world;
/// nullopt if the string lengths do not give a position.
std::optional<Vec3> fingertip_from_counts(const strings::FingerConfig& finger,
                                          std::span<const strings::EncoderChannel> channels,
                                          std::span<const std::int64_t> counts);
inline std::optional<Vec3> fingertip_from_counts(const strings::FingerConfig& finger,
                                                 std::span<const std::int64_t> counts) {
  return fingertip_from_counts(finger, finger.channels, counts);
}

struct StabilityParams {
  double hold_s = 0.5;          ///< the fingertip must hold still this long [s]
  double tolerance_m = 0.0005;  ///< largest change of any of its strings while holding [m]
  double near_m = 0.03;         ///< and be this close to the target by the present calibration [m]
};

/// Watches one finger's counts; `ready()` once it has held still near the target for hold_s.
class StabilityCheck {
 public:
  StabilityCheck(const strings::FingerConfig& finger, const Vec3& p_W_target, StabilityParams params);
  /// A reading at time t [s] of this finger's strings (config order).
  void update(double t_s, std::span<const std::int64_t> counts);
  bool ready() const { return ready_; }
  double held_s() const { return held_s_; }      ///< how long it has held still so far [s]
  double spread_m() const { return spread_m_; }  ///< largest string change over the window [m]
  double distance_m() const { return distance_m_; }  ///< from the target, present calibration [m]
  /// The mean counts over the hold window (rounded to counts).
  std::vector<std::int64_t> sample() const;

 private:
  const strings::FingerConfig& finger_;
  Vec3 target_;
  StabilityParams p_;
  std::deque<std::pair<double, std::vector<std::int64_t>>> window_;
  bool ready_ = false;
  double still_since_ = 0;  ///< when the present still stretch began [s]
  double held_s_ = 0, spread_m_ = 0, distance_m_ = 1e9;
};

/// The simulated user during calibration: the active finger moves from its rest point to the
/// target (smoothly, in `approach_s`) and holds there; the others hover, moving, at their rest
/// points (so they never pass the stability check). Call `activate` when the step changes.
class CalibrationUser final : public device::FingertipSource {
 public:
  CalibrationUser(const strings::DeviceConfig& config, double approach_s = 0.6);
  void activate(int finger, const Vec3& p_W_target, double t_s);
  void goals(double t_s, std::span<Vec3> p_W_goal) override;

 private:
  std::vector<Vec3> rest_;
  device::ScriptedFingertips::Script hover_;
  double approach_s_;
  int finger_ = -1;
  Vec3 from_ = Vec3::Zero(), target_ = Vec3::Zero();
  double t_active_ = 0;
};

/// The device config text with finger `finger`'s channels replaced: `length_at_zero` always,
/// `signs` and `metres_per_count` too with `full` (multi-point). Other text is kept; a comment
/// line notes the calibration. Throws UsageError if the finger's block is not found.
std::string with_finger_channels(const std::string& yaml, const std::string& source,
                                 const std::string& finger,
                                 std::span<const strings::EncoderChannel> channels, bool full,
                                 const std::string& note);

/// Copies an existing file to `path.bak-YYYYmmdd-HHMMSS` (unique) and returns that path; empty if
/// `path` does not exist. Throws UsageError if the copy fails.
std::string keep_previous_version(const std::string& path);

/// Writes `text` to `path`, keeping the previous file as `path.bak-YYYYmmdd-HHMMSS` (returned).
/// The text must parse as a device config first. The file is replaced whole or not at all
/// (core::write_file_atomic), through a symbolic link to the file it names. Throws UsageError,
/// core::ConfigError or core::FileError (naming the path).
std::string write_config_with_backup(const std::string& path, const std::string& text);

}  // namespace spidar::app
