#pragma once
/// Helpers shared by the spidar-mr subcommands.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "spidar/core/result.hpp"
#include "spidar/session/data_path.hpp"
#include "spidar/session/finite_json.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::app {

/// Exit code for bad input (arguments, files, configs).
inline constexpr int kExitBadInput = 2;
/// Exit code when the servo loop latched a fault (or the device stopped) during a run.
inline constexpr int kExitFault = 1;
/// Exit codes when SIGINT / SIGTERM ended a run (128 + the signal, as a shell reports it).
inline constexpr int kExitSigint = 130;
inline constexpr int kExitSigterm = 143;

/// An error the user caused; main prints its message and exits with kExitBadInput.
class UsageError : public SpidarError {
 public:
  using SpidarError::SpidarError;
};

/// Resolves a data file given relative to the project (session::resolve_data_path).
using session::resolve_data_path;

/// Finger by index ("3") or by name ("left_ring"); UsageError listing the valid ones otherwise.
int find_finger(const strings::DeviceConfig& cfg, const std::string& finger);

using session::to_json;

/// UsageError unless lo <= x <= hi (NaN is refused too): "--seconds: expected 0 to 600 s, got nan".
void require_range(double x, double lo, double hi, std::string_view option, std::string_view unit = "");

/// UsageError naming `option` when a path it takes is empty (`what`: what it names, e.g. "a
/// hands YAML file").
void require_path(const std::string& path, std::string_view option, std::string_view what);

/// Makes the output directory `dir` (and its parents) up front, before any input is loaded:
/// UsageError naming `option` and the reason when it cannot (a file in the way, no permission).
void make_output_dir(const std::string& dir, std::string_view option);

/// The largest seed a --seed option takes.
inline constexpr std::uint64_t kMaxSeed = 4294967295u;
/// Check for --seed options: a decimal whole number 0 to kMaxSeed. CLI11 would otherwise map
/// "-1" or "1e30" to some other seed (strtoull wraps and saturates) instead of refusing it.
CLI::Validator seed_check();

/// SpidarError naming the first non-finite number in `j` (session::require_finite_json).
using session::require_finite_json;

/// `x` if finite, else `fallback` (a statistic of an empty or broken set).
inline double finite_or(double x, double fallback) { return std::isfinite(x) ? x : fallback; }

}  // namespace spidar::app
