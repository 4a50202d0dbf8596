#pragma once
/// The hardware boundary: one small interface every string device implements (after CHAI3D's
/// cGenericHapticDevice). A backend reads raw encoder counts and writes raw motor commands; all
/// maths (lengths, positions, tensions) stays in `strings` and the servo loop.
///
/// Threading: `open`, `close`, `read` and `write` are called from one thread (the servo thread
/// once it runs). `request_safe_state` and `status` may be called from any thread.
/// To add a backend, copy src/device/template_device.cpp (docs/adding-a-device.md).
#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::device {

/// Most strings one device serves (SPIDAR-8: 24).
inline constexpr int kMaxDeviceStrings = 32;

/// Fault bits, as reported by `DeviceStatus::faults` and the servo loop.
enum Fault : std::uint32_t {
  kFaultNone = 0,
  kFaultDisconnected = 1u << 0,   ///< port gone, cable pulled, device closed itself
  kFaultReadTimeout = 1u << 1,    ///< no reading within the timeout
  kFaultProtocol = 1u << 2,       ///< corrupt or unexpected frames beyond tolerance
  kFaultOverCurrent = 1u << 3,    ///< the device reports a motor over its current limit
  kFaultEmergencyStop = 1u << 4,  ///< emergency stop pressed (API or hardware button)
  kFaultWatchdog = 1u << 5,       ///< the device or the loop's watchdog tripped
  kFaultDeadlineMiss = 1u << 6,   ///< the servo loop missed its deadline by too much
  kFaultForceStall = 1u << 7,     ///< the force producer stopped delivering
  kFaultStaleCounts = 1u << 8,    ///< the device gave no new reading for too many cycles in a row
  // Host-side checks of the readings (the servo loop; a firmware never sets these bits):
  kFaultWorkspace = 1u << 9,      ///< a solved fingertip left the device's workspace
  kFaultInconsistent = 1u << 10,  ///< a finger's string lengths disagreed for too many cycles
  kFaultEncoderGlitch = 1u << 11, ///< a string's length jumped faster than a fingertip can move
  kFaultFrozenClock = 1u << 12,   ///< the device's clock stopped while the host's ran on
};

/// The bits a device may report in `EncoderReading::status_flags` (docs/protocol.md: bits 0–7).
/// Any other bit set by a device is a protocol fault.
inline constexpr std::uint32_t kDeviceStatusBits = 0xFFu;

/// The name of one fault bit ("over_current"), or nullptr for a bit without a name.
const char* fault_name(std::uint32_t bit);

/// Names of the set fault bits, e.g. "disconnected,read_timeout".
std::string fault_names(std::uint32_t faults);

/// What a device can do; fixed once open.
struct DeviceInfo {
  std::string name;                ///< e.g. "simulated SPIDAR-8", "serial /dev/ttyACM0"
  int string_count = 0;            ///< strings (= encoder channels = motors)
  int counter_bits = 24;           ///< width of the signed, wrapping encoder counters
  std::int32_t command_min = 0;    ///< smallest motor command (DAC counts) = minimum tension
  std::int32_t command_max = 4095; ///< largest motor command (DAC counts)
  /// Readings carry the device's own clock in `EncoderReading::device_time_us`. The servo loop
  /// faults when that clock stops (kFaultFrozenClock); a backend without a clock sets false.
  bool device_clock = true;
};

/// One reading of every encoder.
struct EncoderReading {
  std::int64_t host_time_ns = 0;    ///< host monotonic clock when the reading arrived [ns]
  std::uint32_t device_time_us = 0; ///< device's own clock (wraps) [µs]
  std::uint32_t status_flags = 0;   ///< device status bits (Fault values)
  int string_count = 0;
  std::array<std::int32_t, kMaxDeviceStrings> counts{};  ///< raw signed counter values
  /// 0: a new reading. k > 0: the device had nothing newer (its answer is late), so this is the
  /// previous reading again, returned for the k-th time in a row (same counts, same times).
  /// Backends that never repeat leave it as it is: callers set it to 0 before `read`.
  std::uint32_t repeats = 0;
};

struct DeviceStatus {
  bool open = false;
  std::uint32_t faults = kFaultNone;  ///< latched fault bits
};

class Device {
 public:
  virtual ~Device() = default;

  /// Opens the device. Errors say what failed and where (port, file).
  virtual Status open() = 0;
  /// Puts the motors in the safe state and closes. Idempotent.
  virtual void close() = 0;
  virtual const DeviceInfo& info() const = 0;

  /// Reads all encoder counts. Returns an error (and latches a fault) on disconnect or timeout;
  /// must not block much longer than one servo period on a healthy device. A backend whose
  /// readings arrive asynchronously may return its last reading again with `repeats` > 0 rather
  /// than wait; the servo loop counts those and faults when there are too many in a row.
  virtual Status read(EncoderReading& out) = 0;
  /// Writes one command per string (DAC counts). The backend clamps to
  /// [command_min, command_max] and never drives a motor beyond it.
  virtual Status write(std::span<const std::int32_t> commands) = 0;

  /// Asks for the safe state (every motor at its minimum command) from any thread. The backend
  /// applies it at once where it can, and keeps writing minimum commands until `clear_safe_state`.
  virtual void request_safe_state() = 0;
  /// Leaves the safe state (the servo loop calls this when it starts).
  virtual void clear_safe_state() = 0;
  virtual DeviceStatus status() const = 0;

  /// Whether the device's link can serve `rate_hz` servo cycles per second; the servo loop asks
  /// before it starts and refuses to start on an error (which says what limits the rate and what
  /// would lift it). Default: no known limit. The serial backend checks its baud rate. A wrapper
  /// that forwards to another device must forward this too.
  virtual Status check_rate(double rate_hz) const {
    (void)rate_hz;
    return Ok{};
  }
};

}  // namespace spidar::device
