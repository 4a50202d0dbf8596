#pragma once
/// Helpers shared by the spidar-mr subcommands.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

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

/// Finger by index ("3") or by name ("left_ring"); UsageError naming `option` and listing the
/// valid ones otherwise.
int find_finger(const strings::DeviceConfig& cfg, const std::string& finger, std::string_view option = "--finger");

/// Fingers from a comma-separated list of indices or names ("0,left_index"), in the order given;
/// UsageError naming `option` for an unknown, empty or repeated item.
std::vector<int> parse_finger_list(const strings::DeviceConfig& cfg, const std::string& list,
                                   std::string_view option = "--fingers");

using session::to_json;

/// UsageError unless lo <= x <= hi (NaN is refused too): "--seconds: expected 0 to 600 s, got nan".
/// A subnormal number (1e-320: no quantity a user means) is refused as well.
void require_range(double x, double lo, double hi, std::string_view option, std::string_view unit = "");

/// UsageError unless lo < x <= hi (NaN and subnormal numbers refused): "--tolerance: expected
/// more than 0 and at most 20 mm, got 0".
void require_above(double x, double lo, double hi, std::string_view option, std::string_view unit = "");

/// UsageError naming `option` when a path it takes is empty (`what`: what it names, e.g. "a
/// hands YAML file").
void require_path(const std::string& path, std::string_view option, std::string_view what);

/// Checks, without creating anything, that the output directory `dir` can be made or used:
/// UsageError naming `option` for an empty path, the filesystem's root, a file in the way, or a
/// nearest existing parent that is not a writable folder. Call it before any input is loaded, and
/// make the folder (make_output_dir) only once the inputs are known good, so that a refused run
/// leaves nothing behind.
void check_output_dir(const std::string& dir, std::string_view option);

/// Checks, without creating anything, that the output file `path` can be written: UsageError
/// naming `option` for an empty path, something other than a file in its place, or a nearest
/// existing parent that is not a writable folder (`what`: what it names, e.g. "a PNG file").
void check_output_file(const std::string& path, std::string_view option, std::string_view what);

/// check_output_dir, then makes `dir` (and its parents): UsageError naming `option` and the reason
/// when it cannot.
void make_output_dir(const std::string& dir, std::string_view option);

/// UsageError "NAME: applies `applies`" when `option` was given where it does not apply (e.g.
/// applies = "with --record DIR"): an option that would be ignored is a mistake worth saying.
void refuse_given(const CLI::Option* option, std::string_view applies);

/// UsageError for any option or positional argument of `app` or its parsed subcommands given an
/// empty value (`--seconds ''`): CLI11 would turn it into 0 or the default without a word.
void refuse_empty_values(const CLI::App& app);

/// Check for a number option: lo <= x <= hi, NaN and subnormal numbers refused (CLI::Range lets
/// NaN through); CLI11 names the option in its message.
CLI::Validator range_check(double lo, double hi, std::string_view unit = "");

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
