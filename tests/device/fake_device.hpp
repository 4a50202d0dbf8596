#pragma once
/// A fake `Device` for the transport tests: counts set by the test, records what it is told.
/// Thread-safe, since the emulator calls it from its own thread while the test inspects it.
#include <algorithm>
#include <array>
#include <mutex>
#include <vector>

#include "spidar/device/device.hpp"

namespace spidar::device::testing {

class FakeDevice final : public Device {
 public:
  explicit FakeDevice(int strings, std::int32_t command_min = 0, std::int32_t command_max = 4095) {
    info_.name = "fake";
    info_.string_count = strings;
    info_.command_min = command_min;
    info_.command_max = command_max;
  }

  Status open() override {
    std::lock_guard<std::mutex> l(m_);
    open_ = true;
    return Ok{};
  }
  void close() override {
    std::lock_guard<std::mutex> l(m_);
    open_ = false;
  }
  const DeviceInfo& info() const override { return info_; }

  Status read(EncoderReading& out) override {
    std::lock_guard<std::mutex> l(m_);
    out.string_count = info_.string_count;
    out.status_flags = flags_;
    out.counts = counts_;
    ++reads_;
    return Ok{};
  }
  Status write(std::span<const std::int32_t> commands) override {
    std::lock_guard<std::mutex> l(m_);
    last_.assign(commands.begin(), commands.end());
    ++writes_;
    return Ok{};
  }
  void request_safe_state() override {
    std::lock_guard<std::mutex> l(m_);
    safe_ = true;
    ++safe_requests_;
  }
  void clear_safe_state() override {
    std::lock_guard<std::mutex> l(m_);
    safe_ = false;
  }
  DeviceStatus status() const override {
    std::lock_guard<std::mutex> l(m_);
    return {open_, kFaultNone};
  }

  // --- test side ---
  void set_counts(const std::array<std::int32_t, kMaxDeviceStrings>& c) {
    std::lock_guard<std::mutex> l(m_);
    counts_ = c;
  }
  void set_flags(std::uint32_t f) {
    std::lock_guard<std::mutex> l(m_);
    flags_ = f;
  }
  std::vector<std::int32_t> last_commands() const {
    std::lock_guard<std::mutex> l(m_);
    return last_;
  }
  int writes() const {
    std::lock_guard<std::mutex> l(m_);
    return writes_;
  }
  bool safe() const {
    std::lock_guard<std::mutex> l(m_);
    return safe_;
  }
  int safe_requests() const {
    std::lock_guard<std::mutex> l(m_);
    return safe_requests_;
  }

 private:
  DeviceInfo info_;
  mutable std::mutex m_;
  bool open_ = false;
  std::array<std::int32_t, kMaxDeviceStrings> counts_{};
  std::uint32_t flags_ = 0;
  std::vector<std::int32_t> last_;
  int writes_ = 0;
  int reads_ = 0;
  bool safe_ = false;
  int safe_requests_ = 0;
};

}  // namespace spidar::device::testing
