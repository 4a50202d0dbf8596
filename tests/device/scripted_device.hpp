#pragma once
/// A `Device` whose readings a test scripts: by default every fingertip rests at its rest point
/// (ideal counts for the config's channels), the device clock advances 1000 µs per reading and no
/// status bit is set; a script may change any reading by its index (0, 1, 2, … = servo cycle).
/// It records when the safe state was first requested (as the number of reads done by then) and
/// which writes were all-minimum, so a test can tell in which cycle a fault reached the device.
#include <array>
#include <atomic>
#include <functional>
#include <vector>

#include "spidar/core/clock.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/encoder.hpp"

namespace spidar::device::testing {

class ScriptedDevice final : public Device {
 public:
  /// Changes reading `index` (already filled with the resting defaults) in place.
  using Script = std::function<void(std::uint64_t index, EncoderReading& reading)>;
  static constexpr std::size_t kMaxRecordedWrites = 1 << 16;

  ScriptedDevice(const strings::DeviceConfig& config, Script script)
      : config_(config), script_(std::move(script)), rest_(rest_points(config)) {
    info_.name = "scripted device";
    info_.string_count = config.string_count();
    info_.counter_bits = config.counter_bits;
    info_.command_min = config.command_range().min;
    info_.command_max = config.command_range().max;
    for (std::size_t f = 0; f < config.fingers.size(); ++f)
      set_finger(rest_counts_, static_cast<int>(f), rest_[f]);
  }

  /// Raw counts of every string with finger `f` at `p_W` [m] and the others where they were.
  void set_finger(std::array<std::int32_t, kMaxDeviceStrings>& counts, int f,
                  const Vec3& p_W) const {
    int k = 0;
    for (int g = 0; g < f; ++g) k += config_.fingers[static_cast<std::size_t>(g)].geometry.n;
    const auto& fc = config_.fingers[static_cast<std::size_t>(f)];
    for (int i = 0; i < fc.geometry.n; ++i, ++k) {
      const double l = (fc.geometry.p_WA[i] - p_W).norm();
      counts[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(strings::wrap_counter(
          strings::length_to_counts(fc.channels[static_cast<std::size_t>(i)], l),
          info_.counter_bits));
    }
  }
  const std::vector<Vec3>& rest() const { return rest_; }
  /// First string of finger `f`.
  int first_string(int f) const {
    int k = 0;
    for (int g = 0; g < f; ++g) k += config_.fingers[static_cast<std::size_t>(g)].geometry.n;
    return k;
  }

  Status open() override {
    open_ = true;
    return Ok{};
  }
  void close() override { open_ = false; }
  const DeviceInfo& info() const override { return info_; }
  Status read(EncoderReading& out) override {
    const std::uint64_t index = reads_.load();
    out.host_time_ns = core::monotonic_ns();
    out.device_time_us = static_cast<std::uint32_t>(1000 * index);
    out.status_flags = 0;
    out.string_count = info_.string_count;
    out.counts = rest_counts_;
    if (script_) script_(index, out);
    reads_.fetch_add(1);
    return Ok{};
  }
  Status write(std::span<const std::int32_t> commands) override {
    bool all_min = true;
    for (auto c : commands) all_min = all_min && c == info_.command_min;
    const std::uint64_t index = writes_.fetch_add(1);
    if (index < kMaxRecordedWrites) all_min_[index].store(all_min ? 1 : 2);
    return Ok{};
  }
  void request_safe_state() override {
    std::uint64_t none = kNever;
    first_safe_request_reads_.compare_exchange_strong(none, reads_.load());
    safe_requests_.fetch_add(1);
  }
  void clear_safe_state() override {}
  DeviceStatus status() const override { return {open_.load(), kFaultNone}; }

  // --- test side ---
  static constexpr std::uint64_t kNever = ~std::uint64_t{0};
  std::uint64_t reads() const { return reads_.load(); }
  /// Reads done when the safe state was first requested (k + 1: in the cycle of reading k).
  std::uint64_t first_safe_request_reads() const { return first_safe_request_reads_.load(); }
  int safe_requests() const { return safe_requests_.load(); }
  /// 1: write `index` sent every motor its minimum; 2: it did not; 0: not written (yet).
  int write_all_minimum(std::uint64_t index) const {
    return index < kMaxRecordedWrites ? all_min_[index].load() : 0;
  }

 private:
  const strings::DeviceConfig& config_;
  Script script_;
  std::vector<Vec3> rest_;
  DeviceInfo info_;
  std::array<std::int32_t, kMaxDeviceStrings> rest_counts_{};
  std::atomic<bool> open_{false};
  std::atomic<std::uint64_t> reads_{0}, writes_{0};
  std::atomic<std::uint64_t> first_safe_request_reads_{kNever};
  std::atomic<int> safe_requests_{0};
  std::vector<std::atomic<int>> all_min_ = std::vector<std::atomic<int>>(kMaxRecordedWrites);
};

}  // namespace spidar::device::testing
