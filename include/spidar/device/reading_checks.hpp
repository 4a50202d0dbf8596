#pragma once
/// Checks of each device reading that the servo loop turns into latched faults within the cycle
/// the reading arrives:
///
///   - status bits: every bit the device reports in `EncoderReading::status_flags` (over-current,
///     emergency stop, protocol, watchdog, … — docs/protocol.md, bits 0–7) is a fault of the same
///     name; a bit the protocol does not define is kFaultProtocol. The device's watchdog bit is not
///     taken from the first `kDeviceWatchdogGraceReadings` new readings unless it has been seen
///     clear: a device left alone between sessions sits in its watchdog safe state until the first
///     SetCommands of the new session, so the answer to open()'s Heartbeat still carries the bit.
///   - encoder glitch: a string whose length changed by more than a fingertip moving at
///     `max_fingertip_speed_mps` can change it (|Δl| ≤ |Δp| for a string from a fixed fulcrum)
///     over the time between the two readings — the longest of one servo period, the host's and
///     the device's clocks — plus `kGlitchSlackCounts` counts of noise.
///   - frozen clock: the device's clock (`device_time_us`) reads the same over
///     `max_frozen_clock_readings` new readings in a row while the host's clock runs on. Devices
///     without a clock (`DeviceInfo::device_clock` false) are not checked.
///   - workspace: a solved fingertip outside the fulcrums' box grown by `workspace_margin_m`.
///   - inconsistent: a finger whose lengths do not meet in one point (or are invalid) for more than
///     `max_inconsistent_cycles` new readings in a row.
///
/// Detection runs every cycle and allocates nothing; `describe` writes the text of a finding
/// (what, which finger and string, the value against its bound) into a fixed buffer, called only
/// on the cycle a fault latches. One thread (the servo thread) uses an instance.
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "spidar/device/device.hpp"
#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/device/workspace.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device {

/// Noise and quantisation allowed on top of the speed bound of a string's length change [counts].
inline constexpr double kGlitchSlackCounts = 8.0;
/// New readings at the start of a run whose device watchdog bit is not latched unless the loop
/// has seen the bit clear: the answer to open()'s Heartbeat (see above).
inline constexpr std::uint64_t kDeviceWatchdogGraceReadings = 1;
/// A device clock step longer than this is not believed as the time between two readings [s].
inline constexpr double kMaxBelievedClockStepS = 1.0;

/// The bounds of the checks (copied from `ServoConfig`, which documents and validates them).
struct ReadingLimits {
  double period_s = 1e-3;                 ///< nominal servo period [s]
  double workspace_margin_m = 0.1;        ///< [m]
  int max_inconsistent_cycles = 5;        ///< new readings in a row
  double max_fingertip_speed_mps = 10.0;  ///< [m/s]
  int max_frozen_clock_readings = 10;     ///< new readings in a row
};

/// One finding of one reading. Fields not named for a fault keep their defaults.
struct ReadingFault {
  std::uint32_t fault = 0;         ///< one Fault bit
  std::uint64_t cycle = 0;         ///< servo cycle of the reading
  std::uint32_t status_flags = 0;  ///< the reading's status bits
  int finger = -1;                 ///< finger index; −1: not about one finger
  int string = -1;                 ///< device string index; −1: not about one string
  double value = 0;                ///< what was seen: glitch |Δl| [m], workspace excess [m],
                                   ///< inconsistent / frozen: readings in a row
  double bound = 0;                ///< the bound it broke, same unit
  double dt_s = 0;                 ///< glitch: time the change took [s]; frozen: host time the
                                   ///< device clock stood still [s]
  double residual_m = std::numeric_limits<double>::quiet_NaN();  ///< inconsistent: RMS residual
  double length_m = std::numeric_limits<double>::quiet_NaN();    ///< inconsistent: bad length
  std::int64_t before = 0, after = 0;  ///< glitch: counts; frozen: device time [µs] (after);
                                       ///< protocol: undefined status bits (after)
  int axis = -1;                       ///< workspace: 0, 1, 2 = x, y, z
  double lo_m = 0, hi_m = 0;           ///< workspace: the box along `axis` [m]
  std::array<double, 3> p_W{};         ///< workspace: the solved position [m], world
};

/// The findings of one cycle: at most one per fault bit.
struct ReadingFindings {
  static constexpr int kMax = 16;
  std::array<ReadingFault, kMax> items{};
  int count = 0;
  std::uint32_t faults = 0;  ///< OR of the items' fault bits

  void clear() {
    count = 0;
    faults = 0;
  }
  /// Adds `f` unless its fault is already there (or the list is full).
  void add(const ReadingFault& f) {
    if ((faults & f.fault) || count >= kMax) return;
    items[static_cast<std::size_t>(count++)] = f;
    faults |= f.fault;
  }
};

class ReadingChecks {
 public:
  /// `config` must outlive the checks.
  ReadingChecks(const strings::DeviceConfig& config, const DeviceInfo& device,
                const ReadingLimits& limits);

  /// The device's status bits (every reading, new or repeated; first thing after the read).
  void check_status(const EncoderReading& reading, std::uint64_t cycle, ReadingFindings& out);
  /// A new reading (repeats == 0) after `measured.measure(reading, sample)`: glitch, clock,
  /// workspace, consistency.
  void check_measurement(const EncoderReading& reading, const ServoCycle& measured,
                         const FingertipSample& sample, ReadingFindings& out);

  /// One line: what, which finger/string, the value against its bound (snprintf into `out`, cut
  /// to fit; no allocation). Returns out.data().
  const char* describe(const ReadingFault& f, std::span<char> out) const;

  const Workspace& workspace() const { return workspace_; }
  const ReadingLimits& limits() const { return limits_; }

 private:
  void check_glitch(const EncoderReading& reading, const ServoCycle& measured, std::uint64_t cycle,
                    ReadingFindings& out);
  void check_clock(const EncoderReading& reading, std::uint64_t cycle, ReadingFindings& out);

  const strings::DeviceConfig& config_;
  bool device_clock_;
  ReadingLimits limits_;
  Workspace workspace_;
  std::vector<int> string_finger_;        // finger of each device string
  std::vector<int> finger_offset_;        // first device string of each finger
  std::vector<double> metres_per_count_;  // |metres per count| of each device string
  // State (one thread).
  std::uint64_t new_readings_ = 0;
  bool watchdog_seen_clear_ = false;
  bool have_previous_ = false;
  std::vector<std::int64_t> previous_counts_;
  std::int64_t previous_host_ns_ = 0;
  std::uint32_t previous_device_us_ = 0;
  int frozen_readings_ = 0;                 // new readings in a row on the same device time
  std::int64_t clock_moved_host_ns_ = 0;    // host time of the reading the clock last moved on
  std::vector<int> inconsistent_in_a_row_;  // per finger
};

}  // namespace spidar::device
