#pragma once
/// Helpers shared by the spidar-mr subcommands.
#include <nlohmann/json.hpp>
#include <string>

#include "spidar/core/result.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::app {

/// Exit code for bad input (arguments, files, configs).
inline constexpr int kExitBadInput = 2;

/// An error the user caused; main prints its message and exits with kExitBadInput.
class UsageError : public SpidarError {
 public:
  using SpidarError::SpidarError;
};

/// Resolves a data file given relative to the project (e.g. "configs/spidar8.yaml"): as given if
/// it exists, else under the installed data directory.
std::string resolve_data_path(const std::string& path);

/// Finger by index ("3") or by name ("left_ring"); UsageError listing the valid ones otherwise.
int find_finger(const strings::DeviceConfig& cfg, const std::string& finger);

nlohmann::json to_json(const Vec3& v);

}  // namespace spidar::app
