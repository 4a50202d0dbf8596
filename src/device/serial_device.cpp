#include "spidar/device/serial_device.hpp"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#include "spidar/core/clock.hpp"

namespace spidar::device {
namespace {

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
  if (!(config_.read_timeout_s > 0.0)) return bad("read_timeout_s must be > 0 s");

  Result<SerialPort> port = SerialPort::open(config_.port, config_.baud);
  if (!port) return port.error();
  port_ = std::move(port).value();
  decoder_.reset();
  stats_ = {};
  outstanding_ = false;
  faults_.store(kFaultNone);
  open_.store(true);

  std::size_t n = protocol::encode_set_limits(tx_, next_seq(), {wire_min_, wire_max_});
  if (Status s = send({tx_.data(), n}, "open: sending limits"); !s) {
    close();
    return s;
  }
  const std::uint8_t hb = next_seq();
  n = protocol::encode_heartbeat(tx_, hb);
  if (Status s = send({tx_.data(), n}, "open: sending heartbeat"); !s) {
    close();
    return s;
  }
  expected_seq_ = hb;
  outstanding_ = true;
  return Ok{};
}

void SerialDevice::close() {
  if (!open_.exchange(false)) return;
  if (port_.is_open() && config_.string_count >= 1 && config_.string_count <= kMaxDeviceStrings) {
    std::array<std::int16_t, kMaxDeviceStrings> mins{};
    mins.fill(wire_min_);
    const std::size_t n = protocol::encode_set_commands(
        tx_, next_seq(), {mins.data(), static_cast<std::size_t>(config_.string_count)});
    (void)port_.write_all({tx_.data(), n}, config_.read_timeout_s);  // best effort
  }
  port_.close();
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
  const std::uint8_t seq = next_seq();
  const std::size_t n = protocol::encode_set_commands(tx_, seq, {wire.data(), commands.size()});
  if (Status s = send({tx_.data(), n}, "write"); !s) return s;
  expected_seq_ = seq;
  outstanding_ = true;
  return Ok{};
}

Status SerialDevice::zero_counters(std::uint32_t mask) {
  if (!open_.load(std::memory_order_relaxed)) {
    return fail(kFaultDisconnected, "zero_counters", "device not open", 0);
  }
  const std::size_t n = protocol::encode_zero_counters(tx_, next_seq(), {mask});
  return send({tx_.data(), n}, "zero_counters");
}

Status SerialDevice::read(EncoderReading& out) {
  if (!open_.load(std::memory_order_relaxed)) {
    return fail(kFaultDisconnected, "read", "device not open", 0);
  }
  if (!outstanding_) {
    const std::uint8_t hb = next_seq();
    const std::size_t n = protocol::encode_heartbeat(tx_, hb);
    if (Status s = send({tx_.data(), n}, "read: sending heartbeat"); !s) return s;
    expected_seq_ = hb;
    outstanding_ = true;
  }
  const std::int64_t deadline =
      core::monotonic_ns() + static_cast<std::int64_t>(config_.read_timeout_s * 1e9);
  bool got = false;
  int bad_count = -1;
  protocol::Counts counts;
  for (;;) {
    const double remaining = static_cast<double>(deadline - core::monotonic_ns()) * 1e-9;
    const IoResult r = port_.read_some(rx_, remaining > 0.0 ? remaining : 0.0);
    if (r.status == IoStatus::kTimeout) {
      ++stats_.timeouts;
      outstanding_ = false;
      return fail(kFaultReadTimeout, "read", "no Counts frame within the read timeout", 0);
    }
    if (r.status == IoStatus::kClosed) {
      return fail(kFaultDisconnected, "read", "port closed by the device side", r.error_number);
    }
    if (r.status == IoStatus::kError) {
      return fail(kFaultDisconnected, "read", "read failed", r.error_number);
    }
    decoder_.feed({rx_.data(), r.bytes}, [&](const protocol::Frame& f) {
      if (f.type != protocol::FrameType::kCounts) {
        ++stats_.unexpected;
        return;
      }
      if (f.seq != expected_seq_) {
        ++stats_.stale;
        return;
      }
      if (!protocol::parse(f, counts)) return;  // cannot happen: the decoder checked the length
      if (counts.count != config_.string_count) {
        bad_count = counts.count;
        return;
      }
      got = true;
    });
    if (bad_count >= 0) {
      outstanding_ = false;
      std::string d = "Counts frame with ";
      d += std::to_string(bad_count);
      d += " strings, expected string_count = ";
      d += std::to_string(config_.string_count);
      return fail(kFaultProtocol, "read", d.c_str(), 0);
    }
    if (got) break;
  }
  outstanding_ = false;
  ++stats_.counts_in;
  out.host_time_ns = core::monotonic_ns();
  out.device_time_us = counts.device_time_us;
  out.status_flags = counts.status_flags;
  out.string_count = counts.count;
  std::copy_n(counts.counts.begin(), counts.count, out.counts.begin());
  const std::uint32_t latched = counts.status_flags & ~static_cast<std::uint32_t>(kFaultWatchdog);
  if (latched != 0) faults_.fetch_or(latched, std::memory_order_acq_rel);
  return Ok{};
}

}  // namespace spidar::device
