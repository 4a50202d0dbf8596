#include "spidar/device/serial_device.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#include "spidar/core/clock.hpp"
#include "spidar/core/config.hpp"
#include "spidar/device/link_budget.hpp"

namespace spidar::device {
namespace {

/// First and largest sleep between looks at the port while a read waits [ns]: short enough to
/// take an answer soon after it lands, growing so that long waits cost few wake-ups.
constexpr std::int64_t kFirstWaitSliceNs = 20'000;
constexpr std::int64_t kMaxWaitSliceNs = 1'000'000;

constexpr std::int32_t kInt16Min = std::numeric_limits<std::int16_t>::min();
constexpr std::int32_t kInt16Max = std::numeric_limits<std::int16_t>::max();

std::int16_t to_wire(std::int32_t v) {
  return static_cast<std::int16_t>(std::clamp(v, kInt16Min, kInt16Max));
}

}  // namespace

SerialDevice::SerialDevice(SerialDeviceConfig config) : config_(std::move(config)) {
  info_.name = "serial ";
  info_.name += config_.port;
  info_.string_count = config_.string_count;
  info_.counter_bits = config_.counter_bits;
  info_.command_min = config_.command_min;
  info_.command_max = config_.command_max;
  wire_min_ = to_wire(config_.command_min);
  wire_max_ = to_wire(config_.command_max);
}

SerialDevice::~SerialDevice() { close(); }

Status SerialDevice::fail(std::uint32_t fault, const char* what, const char* detail,
                          int error_number) {
  faults_.fetch_or(fault, std::memory_order_acq_rel);
  std::string msg = info_.name;
  msg += ": ";
  msg += what;
  msg += ": ";
  msg += detail;
  if (error_number != 0) {
    msg += " (";
    msg += std::strerror(error_number);
    msg += ")";
  }
  msg += " [";
  msg += fault_names(fault);
  msg += "]";
  return Error{msg};
}

Status SerialDevice::send(std::span<const std::uint8_t> frame, const char* what) {
  const IoResult r = port_.write_all(frame, config_.read_timeout_s);
  switch (r.status) {
    case IoStatus::kOk:
      ++stats_.frames_out;
      return Ok{};
    case IoStatus::kTimeout:
      return fail(kFaultReadTimeout, what, "the port took no bytes within the read timeout", 0);
    case IoStatus::kClosed:
      return fail(kFaultDisconnected, what, "port closed by the device side", r.error_number);
    case IoStatus::kError:
      break;
  }
  return fail(kFaultDisconnected, what, "write failed", r.error_number);
}

Status SerialDevice::open() {
  const std::string where = info_.name;
  auto bad = [&where](const std::string& detail) {
    std::string msg = where;
    msg += ": ";
    msg += detail;
    return Status(Error{msg});
  };
  if (open_.load()) return Ok{};
  if (config_.port.empty()) return bad("no port given (expected a tty path, e.g. /dev/ttyACM0)");
  if (config_.string_count < 1 || config_.string_count > kMaxDeviceStrings) {
    std::string d = "string_count ";
    d += std::to_string(config_.string_count);
    d += " out of range (expected 1 … ";
    d += std::to_string(kMaxDeviceStrings);
    d += ")";
    return bad(d);
  }
  if (config_.counter_bits < 2 || config_.counter_bits > 32) {
    std::string d = "counter_bits ";
    d += std::to_string(config_.counter_bits);
    d += " out of range (expected 2 … 32)";
    return bad(d);
  }
  if (config_.command_min > config_.command_max) {
    std::string d = "command_min ";
    d += std::to_string(config_.command_min);
    d += " > command_max ";
    d += std::to_string(config_.command_max);
    return bad(d);
  }
  // The servo thread waits up to this long for room to write a frame: bounded, so that a stuck
  // link cannot hold the loop (and its safe state) for longer than a second.
  if (!(config_.read_timeout_s > 0.0 && config_.read_timeout_s <= kMaxReadTimeout_s)) {
    std::string d = "read_timeout_s ";
    d += core::number_for_message(config_.read_timeout_s, 6);
    d += " s out of range (expected more than 0 and at most 1 s)";
    return bad(d);
  }

  Result<SerialPort> port = SerialPort::open(config_.port, config_.baud);
  if (!port) return port.error();
  port_ = std::move(port).value();
  decoder_.reset();
  stats_ = {};
  outstanding_ = false;
  have_reading_ = false;
  held_ = {};
  faults_.store(kFaultNone);
  open_.store(true);

  const std::size_t n = protocol::encode_set_limits(
      tx_, static_cast<std::uint8_t>(next_index()), {wire_min_, wire_max_});
  if (Status s = send({tx_.data(), n}, "open: sending limits"); !s) {
    close();
    return s;
  }
  if (Status s = send_heartbeat("open: sending heartbeat"); !s) {
    close();
    return s;
  }
  return Ok{};
}

Status SerialDevice::send_heartbeat(const char* what) {
  const std::uint64_t index = next_index();
  const std::size_t n = protocol::encode_heartbeat(tx_, static_cast<std::uint8_t>(index));
  if (Status s = send({tx_.data(), n}, what); !s) return s;
  latest_request_ = index;
  outstanding_ = true;
  return Ok{};
}

void SerialDevice::close() {
  if (!open_.exchange(false)) return;
  if (port_.is_open() && config_.string_count >= 1 && config_.string_count <= kMaxDeviceStrings) {
    std::array<std::int16_t, kMaxDeviceStrings> mins{};
    mins.fill(wire_min_);
    const std::size_t n = protocol::encode_set_commands(
        tx_, static_cast<std::uint8_t>(next_index()),
        {mins.data(), static_cast<std::size_t>(config_.string_count)});
    (void)port_.write_all({tx_.data(), n}, config_.read_timeout_s);  // best effort
  }
  port_.close();
}

Status SerialDevice::check_rate(double rate_hz) const {
  // Shorter than two periods, every reading that comes a period late would lose the device.
  if (rate_hz > 0.0 && config_.read_timeout_s < 2.0 / rate_hz) {
    std::string m = info_.name;
    m += ": read_timeout_s ";
    m += core::number_for_message(config_.read_timeout_s, 6);
    m += " s is shorter than two servo periods at ";
    m += core::number_for_message(rate_hz, 6);
    m += " Hz (";
    m += core::number_for_message(2.0 / rate_hz, 6);
    m += " s): expected at least that (raise the read timeout, or the rate)";
    return Error{m};
  }
  if (!config_.check_link_budget || port_.baud_ignored()) return Ok{};
  return check_link_budget(info_.name.c_str(), config_.baud, config_.string_count, rate_hz);
}

DeviceStatus SerialDevice::status() const {
  return {open_.load(std::memory_order_acquire), faults_.load(std::memory_order_acquire)};
}

SerialLinkStats SerialDevice::link_stats() const {
  SerialLinkStats s = stats_;
  s.decoder = decoder_.stats();
  return s;
}

Status SerialDevice::write(std::span<const std::int32_t> commands) {
  if (!open_.load(std::memory_order_relaxed)) {
    return fail(kFaultDisconnected, "write", "device not open", 0);
  }
  if (commands.size() != static_cast<std::size_t>(config_.string_count)) {
    std::string msg = info_.name;
    msg += ": write: ";
    msg += std::to_string(commands.size());
    msg += " commands given, expected one per string (";
    msg += std::to_string(config_.string_count);
    msg += ")";
    return Error{msg};
  }
  std::array<std::int16_t, kMaxDeviceStrings> wire{};
  const bool safe = safe_.load(std::memory_order_acquire);
  for (std::size_t i = 0; i < commands.size(); ++i) {
    wire[i] = safe ? wire_min_
                   : to_wire(std::clamp(commands[i], config_.command_min, config_.command_max));
  }
  const std::uint64_t index = next_index();
  const std::size_t n = protocol::encode_set_commands(tx_, static_cast<std::uint8_t>(index),
                                                      {wire.data(), commands.size()});
  if (Status s = send({tx_.data(), n}, "write"); !s) return s;
  latest_request_ = index;
  outstanding_ = true;
  return Ok{};
}

Status SerialDevice::zero_counters(std::uint32_t mask) {
  if (!open_.load(std::memory_order_relaxed)) {
    return fail(kFaultDisconnected, "zero_counters", "device not open", 0);
  }
  const std::size_t n =
      protocol::encode_zero_counters(tx_, static_cast<std::uint8_t>(next_index()), {mask});
  return send({tx_.data(), n}, "zero_counters");
}

Status SerialDevice::drain(bool& fresh) {
  for (int k = 0; k < kMaxDrainReads; ++k) {
    const IoResult r = port_.read_ready(rx_);
    if (r.status == IoStatus::kClosed) {
      return fail(kFaultDisconnected, "read", "port closed by the device side", r.error_number);
    }
    if (r.status != IoStatus::kOk) {
      return fail(kFaultDisconnected, "read", "read failed", r.error_number);
    }
    if (r.bytes == 0) return Ok{};
    const std::int64_t arrived_ns = core::monotonic_ns();
    int bad_count = -1;
    decoder_.feed({rx_.data(), r.bytes}, [&](const protocol::Frame& f) {
      if (f.type != protocol::FrameType::kCounts) {
        ++stats_.unexpected;
        return;
      }
      // The request this answers: the newest one sent with this sequence number.
      const auto back = static_cast<std::uint8_t>(static_cast<std::uint8_t>(latest_request_) - f.seq);
      if (back > latest_request_ || (have_reading_ && latest_request_ - back <= held_request_)) {
        ++stats_.stale;
        return;
      }
      protocol::Counts counts;
      if (!protocol::parse(f, counts)) return;  // cannot happen: the decoder checked the length
      if (counts.count != config_.string_count) {
        bad_count = counts.count;
        return;
      }
      ++stats_.counts_in;
      held_request_ = latest_request_ - back;
      have_reading_ = true;
      fresh = true;
      if (back == 0) outstanding_ = false;
      held_.host_time_ns = arrived_ns;
      held_.device_time_us = counts.device_time_us;
      held_.status_flags = counts.status_flags;
      held_.string_count = counts.count;
      held_.repeats = 0;
      std::copy_n(counts.counts.begin(), counts.count, held_.counts.begin());
      const std::uint32_t latched =
          counts.status_flags & ~static_cast<std::uint32_t>(kFaultWatchdog);
      if (latched != 0) faults_.fetch_or(latched, std::memory_order_acq_rel);
    });
    if (bad_count >= 0) {
      outstanding_ = false;
      std::string d = "Counts frame with ";
      d += std::to_string(bad_count);
      d += " strings, expected string_count = ";
      d += std::to_string(config_.string_count);
      return fail(kFaultProtocol, "read", d.c_str(), 0);
    }
    if (r.bytes < rx_.size()) return Ok{};  // took all there was
  }
  return Ok{};
}

Status SerialDevice::read(EncoderReading& out) {
  if (!open_.load(std::memory_order_relaxed)) {
    return fail(kFaultDisconnected, "read", "device not open", 0);
  }
  if (!outstanding_) {
    if (Status s = send_heartbeat("read: sending heartbeat"); !s) return s;
  }
  // Wait for the latest answer only as long as allowed; with nothing to fall back on (the first
  // read after open), up to the read timeout.
  const std::int64_t start = core::monotonic_ns();
  const std::int64_t until =
      start + core::s_to_ns(have_reading_ ? config_.reply_wait_s : config_.read_timeout_s);
  std::int64_t slice = kFirstWaitSliceNs;
  bool fresh = false;
  for (;;) {
    if (Status s = drain(fresh); !s) return s;
    if (!outstanding_) break;
    const std::int64_t now = core::monotonic_ns();
    if (now >= until) break;
    core::sleep_until_ns(std::min(now + slice, until));
    slice = std::min(2 * slice, kMaxWaitSliceNs);
  }
  if (fresh) {
    if (outstanding_) ++stats_.behind;
    out = held_;
    return Ok{};
  }
  const std::int64_t now = core::monotonic_ns();
  if (!have_reading_ || now - held_.host_time_ns > core::s_to_ns(config_.read_timeout_s)) {
    ++stats_.timeouts;
    outstanding_ = false;  // the next read asks again
    return fail(kFaultReadTimeout, "read",
                have_reading_ ? "no new Counts frame within the read timeout"
                              : "no Counts frame within the read timeout",
                0);
  }
  ++stats_.repeated;
  ++held_.repeats;
  out = held_;
  return Ok{};
}

}  // namespace spidar::device
