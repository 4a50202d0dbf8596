#pragma once
/// The device side of the wire protocol, as a microcontroller firmware would run it, served on a
/// file descriptor (a pty master, a socket, a real tty) and backed by any `Device` (the simulated
/// SPIDAR-8, a fake in tests). `spidar-mr emulate-device --pty` runs one of these.
///
/// Firmware behaviour (docs/protocol.md):
///   - SetCommands: clamped to the limits in force, written to the backend, answered by Counts;
///     leaves the watchdog safe state. A command count other than the backend's string count is
///     refused (answered by Counts with kFaultProtocol set, nothing applied).
///   - Heartbeat: answered by Counts.
///   - SetLimits: intersected with the backend's own limits; refused if empty. Not answered.
///   - ZeroCounters: the current count of each masked string becomes its zero. Not answered.
///   - Counts answer the request's sequence number; device time is µs since construction; status
///     flags = watchdog | backend reading flags | backend status faults.
///   - Watchdog: once a first SetCommands or Heartbeat has arrived, if none arrives for
///     heartbeat_timeout_s the backend is put in its safe state and kFaultWatchdog is set in the
///     status flags until the next SetCommands.
/// The backend must already be open; the emulator neither opens nor closes it. It calls the
/// backend from the thread that runs poll_once/run only.
#include <atomic>
#include <cstdint>
#include <mutex>

#include "spidar/core/result.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/protocol.hpp"

namespace spidar::device {

/// Longest heartbeat timeout a device may be given [s]: its watchdog must stop the motors
/// within a second of losing the host (a timeout of 1e9 s would switch the watchdog off).
inline constexpr double kMaxHeartbeatTimeoutS = 1.0;

struct DeviceEmulatorOptions {
  /// Watchdog: longest gap between commands/heartbeats [s], in (0, kMaxHeartbeatTimeoutS].
  double heartbeat_timeout_s = 0.1;
};

/// Ok, or an error saying which option is out of range and what is expected.
Status validate(const DeviceEmulatorOptions& options);

struct EmulatorCounters {
  std::uint64_t frames_in = 0;       ///< valid frames decoded
  std::uint64_t frames_out = 0;      ///< Counts frames written
  std::uint64_t rejected = 0;        ///< valid frames refused (wrong count, empty limits, wrong type)
  std::uint64_t watchdog_trips = 0;  ///< times the heartbeat watchdog put the backend in safe state
  std::uint64_t io_errors = 0;       ///< failed or timed-out reads/writes, hang-ups
  protocol::DecoderStats decoder;    ///< CRC, length and type errors, noise
};

class DeviceEmulator {
 public:
  /// Serves `fd` (not owned, not closed) with `backend` (must outlive the emulator). Throws
  /// SpidarError if the options are invalid (`validate`).
  DeviceEmulator(Device& backend, int fd, DeviceEmulatorOptions options = {});

  /// Waits up to `timeout_s` [s] for host bytes (less if the watchdog is due), handles every
  /// complete frame, then runs the watchdog. Errors: the host side hung up or the fd failed.
  Status poll_once(double timeout_s);
  /// Calls poll_once until `stop` is set; after an error waits 1 ms and goes on (a host may
  /// reopen the port).
  void run(const std::atomic<bool>& stop);

  /// Any thread.
  EmulatorCounters counters() const;
  /// Any thread: true while the watchdog holds the backend in its safe state.
  bool watchdog_tripped() const { return tripped_.load(std::memory_order_acquire); }

 private:
  void handle(const protocol::Frame& f, std::int64_t now_ns);
  void answer(std::uint8_t seq, std::uint32_t extra_flags, std::int64_t now_ns);
  void feed_watchdog(std::int64_t now_ns);
  void check_watchdog(std::int64_t now_ns);
  void publish_counters();

  Device& backend_;
  int fd_;
  DeviceEmulatorOptions options_;
  std::int64_t start_ns_;
  protocol::FrameDecoder decoder_;
  std::int32_t limit_min_;
  std::int32_t limit_max_;
  std::array<std::int32_t, kMaxDeviceStrings> zero_offset_{};
  EncoderReading reading_;
  bool armed_ = false;
  std::int64_t last_feed_ns_ = 0;
  std::atomic<bool> tripped_{false};
  EmulatorCounters counters_;  ///< owned by the serving thread
  mutable std::mutex published_mutex_;
  EmulatorCounters published_;  ///< copy for other threads
};

}  // namespace spidar::device
