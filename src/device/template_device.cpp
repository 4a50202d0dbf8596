// Template for a new hardware backend: copy this file, rename TemplateDevice, and fill in the
// four marked places. See docs/adding-a-device.md. It compiles as is (against a fake in-memory
// "hardware") and tests/device builds it, so the template never rots.
#include <algorithm>
#include <atomic>
#include <memory>
#include <vector>

#include "spidar/core/clock.hpp"
#include "spidar/device/device.hpp"

namespace spidar::device {

class TemplateDevice final : public Device {
 public:
  explicit TemplateDevice(int string_count) {
    info_.name = "template device";
    info_.string_count = string_count;
    info_.counter_bits = 24;   // (1) your counters' width
    info_.command_min = 0;     //     DAC count for the minimum tension
    info_.command_max = 4095;  //     full-scale DAC count
    info_.device_clock = false;  //   true if read() fills device_time_us from the hardware's clock
    hw_counts_.assign(string_count, 0);
    hw_commands_.assign(string_count, 0);
  }

  Status open() override {
    // (2) Open your hardware here; on failure say what and where:
    //     return Error{"template device: /dev/foo: permission denied"};
    open_ = true;
    faults_ = kFaultNone;
    return Ok{};
  }

  void close() override {
    request_safe_state();
    (void)apply_commands();  // closing: nothing more to report
    open_ = false;
  }

  const DeviceInfo& info() const override { return info_; }

  Status read(EncoderReading& out) override {
    if (!open_) return Error{info_.name + ": read while closed"};
    // (3) Read every counter from your hardware. On a lost device, latch the fault and return
    //     an error: faults_ |= kFaultDisconnected; return Error{...};
    out.host_time_ns = core::monotonic_ns();
    out.device_time_us = 0;  // the hardware's own µs clock, if it has one (see device_clock)
    out.status_flags = faults_.load();
    out.string_count = info_.string_count;
    for (int i = 0; i < info_.string_count; ++i) out.counts[i] = hw_counts_[i];
    return Ok{};
  }

  Status write(std::span<const std::int32_t> commands) override {
    if (!open_) return Error{info_.name + ": write while closed"};
    if (static_cast<int>(commands.size()) != info_.string_count) {
      return Error{info_.name + ": expected " + std::to_string(info_.string_count) + " commands"};
    }
    for (int i = 0; i < info_.string_count; ++i) {
      hw_commands_[i] = std::clamp(commands[i], info_.command_min, info_.command_max);
    }
    return apply_commands();
  }

  void request_safe_state() override { safe_.store(true); }
  void clear_safe_state() override { safe_.store(false); }
  DeviceStatus status() const override { return {open_, faults_.load()}; }

  /// Test hook of the fake hardware: what the motors get.
  std::span<const std::int32_t> motor_outputs() const { return hw_commands_; }

 private:
  Status apply_commands() {
    // (4) Send the commands to your motors; in the safe state send the minimum instead.
    if (safe_.load()) std::fill(hw_commands_.begin(), hw_commands_.end(), info_.command_min);
    return Ok{};
  }

  DeviceInfo info_;
  bool open_ = false;
  std::atomic<bool> safe_{true};
  std::atomic<std::uint32_t> faults_{kFaultNone};
  std::vector<std::int32_t> hw_counts_, hw_commands_;  // stand-ins for the hardware
};

/// Factory so the template can be instantiated from tests.
std::unique_ptr<Device> make_template_device(int string_count) {
  return std::make_unique<TemplateDevice>(string_count);
}

}  // namespace spidar::device
