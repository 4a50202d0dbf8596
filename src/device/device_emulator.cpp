#include "spidar/device/device_emulator.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "spidar/core/clock.hpp"
#include "spidar/device/serial_port.hpp"
#include "spidar/strings/encoder.hpp"

namespace spidar::device {

Status validate(const DeviceEmulatorOptions& options) {
  const double t = options.heartbeat_timeout_s;
  if (t > 0.0 && t <= kMaxHeartbeatTimeoutS) return Ok{};
  char msg[256];
  std::snprintf(msg, sizeof msg,
                "device emulator: heartbeat timeout %g s is out of range; expected > 0 and <= %g s "
                "(the device's watchdog must stop the motors within %g s of losing the host)",
                t, kMaxHeartbeatTimeoutS, kMaxHeartbeatTimeoutS);
  return Error{std::string(msg)};
}

DeviceEmulator::DeviceEmulator(Device& backend, int fd, DeviceEmulatorOptions options)
    : backend_(backend),
      fd_(fd),
      options_(options),
      start_ns_(core::monotonic_ns()),
      limit_min_(backend.info().command_min),
      limit_max_(backend.info().command_max) {
  if (Status s = validate(options_); !s) throw SpidarError(s.error().message);
}

EmulatorCounters DeviceEmulator::counters() const {
  std::lock_guard<std::mutex> lock(published_mutex_);
  return published_;
}

void DeviceEmulator::publish_counters() {
  counters_.decoder = decoder_.stats();
  std::lock_guard<std::mutex> lock(published_mutex_);
  published_ = counters_;
}

void DeviceEmulator::feed_watchdog(std::int64_t now_ns) {
  armed_ = true;
  last_feed_ns_ = now_ns;
}

void DeviceEmulator::check_watchdog(std::int64_t now_ns) {
  if (!armed_ || tripped_.load(std::memory_order_relaxed)) return;
  const auto timeout_ns = static_cast<std::int64_t>(options_.heartbeat_timeout_s * 1e9);
  if (now_ns - last_feed_ns_ > timeout_ns) {
    // Why before what: whoever sees the backend in its safe state also sees the trip counted
    // (SerialDevice.HeartbeatTimeoutPutsBackendInSafeState read the flag in between under TSan).
    tripped_.store(true, std::memory_order_release);
    ++counters_.watchdog_trips;
    publish_counters();
    backend_.request_safe_state();
  }
}

void DeviceEmulator::answer(std::uint8_t seq, std::uint32_t extra_flags, std::int64_t now_ns) {
  const DeviceInfo& info = backend_.info();
  const int n = std::clamp(info.string_count, 0, kMaxDeviceStrings);
  protocol::Counts c;
  c.device_time_us = static_cast<std::uint32_t>((now_ns - start_ns_) / 1000);
  c.count = n;
  std::uint32_t flags = extra_flags | backend_.status().faults;
  if (backend_.read(reading_)) {
    flags |= reading_.status_flags;
  } else {
    flags |= kFaultReadTimeout;  // the last good counts go out again
  }
  if (tripped_.load(std::memory_order_relaxed)) flags |= kFaultWatchdog;
  c.status_flags = flags;
  const int bits = std::clamp(info.counter_bits, 2, 32);
  for (int i = 0; i < n; ++i) {
    const std::int64_t raw = std::int64_t{reading_.counts[i]} - zero_offset_[i];
    c.counts[i] = static_cast<std::int32_t>(strings::wrap_counter(raw, bits));
  }
  std::array<std::uint8_t, protocol::kMaxFrameSize> buf{};
  const std::size_t len = protocol::encode_counts(buf, seq, c);
  const IoResult r = write_all(fd_, {buf.data(), len}, 0.1);
  if (r.status == IoStatus::kOk) {
    ++counters_.frames_out;
  } else {
    ++counters_.io_errors;
  }
}

void DeviceEmulator::handle(const protocol::Frame& f, std::int64_t now_ns) {
  ++counters_.frames_in;
  const DeviceInfo& info = backend_.info();
  switch (f.type) {
    case protocol::FrameType::kSetCommands: {
      protocol::SetCommands m;
      feed_watchdog(now_ns);
      if (!protocol::parse(f, m) || m.count != info.string_count) {
        ++counters_.rejected;
        answer(f.seq, kFaultProtocol, now_ns);
        return;
      }
      if (tripped_.load(std::memory_order_relaxed)) {
        tripped_.store(false, std::memory_order_release);
        backend_.clear_safe_state();
      }
      std::array<std::int32_t, kMaxDeviceStrings> cmd{};
      for (int i = 0; i < m.count; ++i) {
        cmd[i] = std::clamp(std::int32_t{m.commands[i]}, limit_min_, limit_max_);
      }
      (void)backend_.write({cmd.data(), static_cast<std::size_t>(m.count)});
      answer(f.seq, 0, now_ns);
      return;
    }
    case protocol::FrameType::kHeartbeat:
      feed_watchdog(now_ns);
      answer(f.seq, 0, now_ns);
      return;
    case protocol::FrameType::kSetLimits: {
      protocol::SetLimits m;
      if (!protocol::parse(f, m)) break;
      const std::int32_t lo = std::max<std::int32_t>(m.command_min, info.command_min);
      const std::int32_t hi = std::min<std::int32_t>(m.command_max, info.command_max);
      if (lo > hi) break;
      limit_min_ = lo;
      limit_max_ = hi;
      return;
    }
    case protocol::FrameType::kZeroCounters: {
      protocol::ZeroCounters m;
      if (!protocol::parse(f, m) || !backend_.read(reading_)) break;
      for (int i = 0; i < std::min(info.string_count, kMaxDeviceStrings); ++i) {
        if (m.mask & (1u << i)) zero_offset_[i] = reading_.counts[i];
      }
      return;
    }
    case protocol::FrameType::kCounts:
      break;  // device→host type sent to the device
  }
  ++counters_.rejected;
}

Status DeviceEmulator::poll_once(double timeout_s) {
  std::int64_t now = core::monotonic_ns();
  double wait = timeout_s;
  if (armed_ && !tripped_.load(std::memory_order_relaxed)) {
    const double due =
        options_.heartbeat_timeout_s - static_cast<double>(now - last_feed_ns_) * 1e-9;
    wait = std::min(wait, std::max(due + 1e-4, 0.0));
  }
  std::array<std::uint8_t, 512> buf{};
  const IoResult r = read_some(fd_, buf, wait);
  now = core::monotonic_ns();
  Status status = Ok{};
  if (r.status == IoStatus::kOk) {
    decoder_.feed({buf.data(), r.bytes}, [&](const protocol::Frame& f) { handle(f, now); });
  } else if (r.status == IoStatus::kClosed) {
    ++counters_.io_errors;
    status = Error{"device emulator: the host side of the port hung up"};
  } else if (r.status == IoStatus::kError) {
    ++counters_.io_errors;
    std::string msg = "device emulator: read failed on fd ";
    msg += std::to_string(fd_);
    msg += " (errno ";
    msg += std::to_string(r.error_number);
    msg += ")";
    status = Error{msg};
  }
  check_watchdog(core::monotonic_ns());
  publish_counters();
  return status;
}

void DeviceEmulator::run(const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_acquire)) {
    if (!poll_once(0.01)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace spidar::device
