#pragma once
/// Host side of the serial transport: a `Device` that talks the wire protocol
/// (spidar/device/protocol.hpp, docs/protocol.md) to a microcontroller SPIDAR over a tty.
///
/// The exchange: every request is answered by one Counts frame echoing its sequence number.
///   - `open()` opens the port, sends SetLimits (not answered) and a Heartbeat;
///   - `write()` sends SetCommands (answered);
///   - `read()` takes what has arrived and keeps the newest Counts frame, i.e. the one answering
///     the most recent request (answers to requests older than the reading it holds are dropped
///     as stale). If the answer to the latest request is not there yet it waits for it at most
///     `reply_wait_s` (default 0: not at all), then returns the newest reading it has: a new one,
///     or, if nothing newer came, the previous one again with `EncoderReading::repeats` > 0. It
///     never waits on the kernel's tty machinery (see `read_ready`), so a servo cycle is not
///     coupled to the link's round trip: "read, compute, write" reads, at the start of cycle k,
///     the answer to cycle k−1's commands when it has arrived, and otherwise runs on the last
///     counts (the servo loop counts those cycles and faults after too many in a row). If no
///     request is outstanding (two reads in a row, or after a timeout) it sends a Heartbeat first.
///   - The first read after `open()` has no reading to fall back on: it waits up to
///     `read_timeout_s` for one.
/// With `reply_wait_s` above the link's round trip the device behaves as a strict
/// request → answer exchange (tools and tests that write, then read the answer to that write).
///
/// Faults latched in `status()`: kFaultDisconnected (port gone: EOF, EIO, hang-up, write failed),
/// kFaultReadTimeout (no new Counts frame for read_timeout_s, or the port would not take a frame
/// within it), kFaultProtocol (Counts with the wrong string count), and the device-reported bits
/// of every Counts frame except kFaultWatchdog, which the device raises and clears itself (it is
/// reported per reading in `EncoderReading::status_flags`). `open()` clears the latched faults.
///
/// The port is held exclusively (SerialPort::open): a second open, from this or another process,
/// fails with "serial port PATH: in use by another process".
///
/// No allocation in `read()`/`write()` unless they return an error.
#include <atomic>
#include <cstdint>
#include <span>
#include <string>

#include "spidar/device/device.hpp"
#include "spidar/device/protocol.hpp"
#include "spidar/device/serial_port.hpp"

namespace spidar::device {

/// The longest SerialDeviceConfig::read_timeout_s [s]: a write waits this long at most.
inline constexpr double kMaxReadTimeout_s = 1.0;

struct SerialDeviceConfig {
  std::string port;            ///< tty path, e.g. /dev/ttyACM0 or a pty slave
  int baud = 921600;           ///< a standard rate (see baud_to_speed)
  int string_count = 0;        ///< strings the device serves (1 … kMaxDeviceStrings)
  int counter_bits = 24;       ///< width of the device's signed, wrapping counters
  std::int32_t command_min = 0;     ///< smallest motor command [DAC counts]
  std::int32_t command_max = 4095;  ///< largest motor command [DAC counts]
  /// The device is lost (read_timeout fault) when no new Counts frame has arrived for this long;
  /// also the longest the first read after open() waits, and a write waits for room [s].
  /// open() takes (0, kMaxReadTimeout_s]; check_rate wants at least two servo periods.
  double read_timeout_s = 0.05;
  /// Longest a read waits for the answer to the latest request before it returns the newest
  /// reading it has [s]. 0: never wait (servo loops: the answer to the previous cycle's write has
  /// had a whole period to arrive). Keep it well below the servo period.
  double reply_wait_s = 0.0;
  /// `check_rate` refuses a servo rate whose SetCommands + Counts frames do not fit the baud rate
  /// (link_budget.hpp). Skipped by itself on USB CDC-ACM ports (the baud rate is ignored there);
  /// false skips it on any port (e.g. a pseudo-terminal standing in for a faster transport).
  bool check_link_budget = true;
};

/// Counters of the host side of the link.
struct SerialLinkStats {
  std::uint64_t frames_out = 0;  ///< frames written
  std::uint64_t counts_in = 0;   ///< Counts frames newer than the reading held, each taken as it
  std::uint64_t stale = 0;       ///< Counts frames no newer than the reading held, dropped
  std::uint64_t unexpected = 0;  ///< valid frames of a host→device type, dropped
  std::uint64_t timeouts = 0;    ///< reads that failed with read_timeout
  std::uint64_t behind = 0;      ///< reads that returned a new reading, but the answer to an
                                 ///< earlier request than the latest (the latest was late)
  std::uint64_t repeated = 0;    ///< reads that found nothing newer and repeated the last reading
  protocol::DecoderStats decoder;  ///< CRC, length, type errors, noise
};

class SerialDevice final : public Device {
 public:
  explicit SerialDevice(SerialDeviceConfig config);
  ~SerialDevice() override;

  /// Checks the configuration, opens the port, sends SetLimits and a Heartbeat.
  Status open() override;
  /// Sends minimum commands (best effort) and closes the port. Idempotent.
  void close() override;
  const DeviceInfo& info() const override { return info_; }

  Status read(EncoderReading& out) override;
  /// Sends one SetCommands frame. Commands are clamped to [command_min, command_max] and to the
  /// int16 range; in the safe state every motor gets command_min.
  Status write(std::span<const std::int32_t> commands) override;

  /// Any thread: from the next write on, only minimum commands go out. The device's own
  /// watchdog covers the time until then.
  void request_safe_state() override { safe_.store(true, std::memory_order_release); }
  void clear_safe_state() override { safe_.store(false, std::memory_order_release); }
  DeviceStatus status() const override;

  /// The link budget at `rate_hz` (link_budget.hpp): an error naming the port, baud rate,
  /// strings, rate and the minimum baud rate needed when the frames of one cycle do not fit.
  /// Ok on CDC-ACM ports and with `check_link_budget` false.
  Status check_rate(double rate_hz) const override;

  /// Asks the device to zero the counters of the strings in `mask` (bit i = string i).
  Status zero_counters(std::uint32_t mask = 0xFFFFFFFFu);

  /// Link counters; call from the thread that reads and writes.
  SerialLinkStats link_stats() const;
  const SerialDeviceConfig& config() const { return config_; }

 private:
  Status send(std::span<const std::uint8_t> frame, const char* what);
  /// Sends a Heartbeat and makes it the latest request.
  Status send_heartbeat(const char* what);
  Status fail(std::uint32_t fault, const char* what, const char* detail, int error_number);
  /// Reads and decodes what the port holds, without waiting; `fresh` is set if a Counts frame
  /// newer than the held reading arrived.
  Status drain(bool& fresh);
  /// Numbers the next frame: its index among all frames sent; the sequence number on the wire
  /// is the index's low byte.
  std::uint64_t next_index() { return frames_numbered_++; }

  static constexpr int kMaxDrainReads = 8;  ///< reads per drain (a flooding device cannot hold us)

  SerialDeviceConfig config_;
  DeviceInfo info_;
  SerialPort port_;
  protocol::FrameDecoder decoder_;
  std::int16_t wire_min_ = 0;  ///< command_min clamped to int16
  std::int16_t wire_max_ = 0;  ///< command_max clamped to int16
  std::uint64_t frames_numbered_ = 0;
  std::uint64_t latest_request_ = 0;  ///< index of the latest answered-type request
  bool outstanding_ = false;          ///< the latest request's answer has not arrived yet
  bool have_reading_ = false;         ///< held_ holds a reading (since open())
  std::uint64_t held_request_ = 0;    ///< index of the request held_ answers
  EncoderReading held_;               ///< the newest reading
  std::array<std::uint8_t, protocol::kMaxFrameSize> tx_{};
  std::array<std::uint8_t, 512> rx_{};
  SerialLinkStats stats_;
  std::atomic<bool> open_{false};
  std::atomic<bool> safe_{false};
  std::atomic<std::uint32_t> faults_{kFaultNone};
};

}  // namespace spidar::device
