#pragma once
/// A string device's configuration (configs/spidar8.yaml, configs/spidar-g4.yaml): fulcrum
/// layout per fingertip, encoder channels, motor drive and tension limits, validated on load.
#include <string>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/strings/encoder.hpp"
#include "spidar/strings/motor.hpp"
#include "spidar/strings/point_geometry.hpp"
#include "spidar/strings/string_set.hpp"

namespace spidar::strings {

/// The most fingertips and strings a device config may have: the servo loop's samples carry 8
/// fingertips and the wire protocol (docs/protocol.md) 32 strings (device::kMaxFingers and
/// device::kMaxDeviceStrings, checked equal where both are known).
inline constexpr int kMaxConfigFingers = 8;
inline constexpr int kMaxConfigStrings = 32;

struct FingerConfig {
  std::string name;                      ///< e.g. "left_index"
  std::string hand;                      ///< "left", "right" or empty
  int unit = -1;                         ///< the device's unit number 0..7 if documented, else −1
  PointGeometry geometry;                ///< fulcrums [m], world, with closed-form constants
  std::vector<EncoderChannel> channels;  ///< one per string
};

struct DeviceConfig {
  std::string name;
  std::string source;                     ///< file it was loaded from
  Vec3 p_W_centre = Vec3::Zero();         ///< frame centre = pole tip [m], world
  int counter_bits = 24;
  MotorModel motor;
  TensionLimits tension;                  ///< as configured
  std::vector<FingerConfig> fingers;

  int string_count() const;
  /// Index of finger `finger`'s first string among the device's strings (they are numbered
  /// finger by finger in config order: its strings are first_string(f) … + geometry.n − 1).
  int first_string(int finger) const;
  /// Limits the drive can actually deliver: [max(t_min, drive min), min(t_max, drive max)].
  TensionLimits effective_limits() const;
  /// Motor commands [DAC counts] for the effective minimum and maximum tension.
  struct CommandRange {
    std::int32_t min = 0, max = 0;
  };
  CommandRange command_range() const;
};

/// Parses and validates a device config. Throws core::ConfigError naming file:line: key. Besides
/// types and ranges: finger names non-empty and unique, units 0..7 and unique, at most
/// kMaxConfigFingers fingers and kMaxConfigStrings strings, and the frame centre inside the convex
/// hull of all fulcrums.
DeviceConfig parse_device_config(const core::ConfigNode& root);
/// Loads and validates a device config file.
DeviceConfig load_device_config(const std::string& path);

/// The lengths each string has with the fingertip at p_WF [m].
StringVec string_lengths(const PointGeometry& geometry, const Vec3& p_WF);

}  // namespace spidar::strings
