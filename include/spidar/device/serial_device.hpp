#pragma once
/// Host side of the serial transport: a `Device` that talks the wire protocol
/// (spidar/device/protocol.hpp, docs/protocol.md) to a microcontroller SPIDAR over a tty.
///
/// The exchange, one request → one answer:
///   - `open()` opens the port, sends SetLimits (not answered) and a Heartbeat;
///   - `write()` sends SetCommands; the device answers it with one Counts frame, echoing its
///     sequence number;
///   - `read()` waits for the Counts frame answering the latest request (older answers are
///     dropped as stale). If no request is outstanding (two reads in a row, or after a timeout)
///     it sends a Heartbeat first and waits for its answer (polling).
/// A servo cycle "read, compute, write" therefore reads the answer to the previous cycle's write,
/// which arrived while the host was computing.
///
/// Faults latched in `status()`: kFaultDisconnected (port gone: EOF, EIO, hang-up, write failed),
/// kFaultReadTimeout (no answer within read_timeout_s, or the port would not take a frame within
/// it), kFaultProtocol (Counts with the wrong string count), and the device-reported bits of every
/// Counts frame except kFaultWatchdog, which the device raises and clears itself (it is reported
/// per reading in `EncoderReading::status_flags`). `open()` clears the latched faults.
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

struct SerialDeviceConfig {
  std::string port;            ///< tty path, e.g. /dev/ttyACM0 or a pty slave
  int baud = 921600;           ///< a standard rate (see baud_to_speed)
  int string_count = 0;        ///< strings the device serves (1 … kMaxDeviceStrings)
  int counter_bits = 24;       ///< width of the device's signed, wrapping counters
  std::int32_t command_min = 0;     ///< smallest motor command [DAC counts]
  std::int32_t command_max = 4095;  ///< largest motor command [DAC counts]
  double read_timeout_s = 0.05;     ///< longest a read waits for its Counts frame [s]
};

/// Counters of the host side of the link.
struct SerialLinkStats {
  std::uint64_t frames_out = 0;     ///< frames written
  std::uint64_t counts_in = 0;      ///< Counts frames accepted as readings
  std::uint64_t stale = 0;          ///< Counts frames answering an older request, dropped
  std::uint64_t unexpected = 0;     ///< valid frames of a host→device type, dropped
  std::uint64_t timeouts = 0;       ///< reads that timed out
  protocol::DecoderStats decoder;   ///< CRC, length, type errors, noise
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

  /// Asks the device to zero the counters of the strings in `mask` (bit i = string i).
  Status zero_counters(std::uint32_t mask = 0xFFFFFFFFu);

  /// Link counters; call from the thread that reads and writes.
  SerialLinkStats link_stats() const;
  const SerialDeviceConfig& config() const { return config_; }

 private:
  Status send(std::span<const std::uint8_t> frame, const char* what);
  Status fail(std::uint32_t fault, const char* what, const char* detail, int error_number);
  std::uint8_t next_seq() { return seq_++; }

  SerialDeviceConfig config_;
  DeviceInfo info_;
  SerialPort port_;
  protocol::FrameDecoder decoder_;
  std::int16_t wire_min_ = 0;  ///< command_min clamped to int16
  std::int16_t wire_max_ = 0;  ///< command_max clamped to int16
  std::uint8_t seq_ = 0;
  std::uint8_t expected_seq_ = 0;  ///< sequence number of the latest request
  bool outstanding_ = false;       ///< a request's answer has not been read yet
  std::array<std::uint8_t, protocol::kMaxFrameSize> tx_{};
  std::array<std::uint8_t, 512> rx_{};
  SerialLinkStats stats_;
  std::atomic<bool> open_{false};
  std::atomic<bool> safe_{false};
  std::atomic<std::uint32_t> faults_{kFaultNone};
};

}  // namespace spidar::device
