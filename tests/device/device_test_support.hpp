#pragma once
#include <algorithm>
#include <atomic>
#include <climits>
#include <memory>
#include <string>

#include "spidar/device/force_source.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device::testing {

inline bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

/// Asks every fingertip for a force, so healthy cycles send commands above the minimum.
struct Pushing final : ForceSource {
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
    out.t_ns = in.t_ns;
    for (int f = 0; f < kMaxFingers; ++f) out.set_force(f, Vec3(0.5, -0.5, 1.0));
  }
};

inline const strings::DeviceConfig& spidar8() {
  static const auto cfg =
      strings::load_device_config(std::string(SPIDAR_SOURCE_DIR) + "/configs/spidar8.yaml");
  return cfg;
}

inline std::shared_ptr<FingertipSource> hovering(const strings::DeviceConfig& cfg) {
  return std::make_shared<ScriptedFingertips>(hovering_hands(rest_points(cfg)));
}

/// Wraps a device and records the extreme commands written (any thread may read them).
class RecordingDevice final : public Device {
 public:
  explicit RecordingDevice(Device& inner) : inner_(inner) {}
  Status open() override { return inner_.open(); }
  void close() override { inner_.close(); }
  const DeviceInfo& info() const override { return inner_.info(); }
  Status read(EncoderReading& out) override { return inner_.read(out); }
  Status write(std::span<const std::int32_t> c) override {
    for (auto v : c) {
      min_.store(std::min(min_.load(), v));
      max_.store(std::max(max_.load(), v));
    }
    writes_.fetch_add(1);
    return inner_.write(c);
  }
  void request_safe_state() override {
    safe_requests_.fetch_add(1);
    inner_.request_safe_state();
  }
  void clear_safe_state() override { inner_.clear_safe_state(); }
  DeviceStatus status() const override { return inner_.status(); }
  Status check_rate(double rate_hz) const override { return inner_.check_rate(rate_hz); }

  std::int32_t min_command() const { return min_.load(); }
  std::int32_t max_command() const { return max_.load(); }
  int writes() const { return writes_.load(); }
  int safe_requests() const { return safe_requests_.load(); }

 private:
  Device& inner_;
  std::atomic<std::int32_t> min_{INT_MAX}, max_{INT_MIN};
  std::atomic<int> writes_{0}, safe_requests_{0};
};

}  // namespace spidar::device::testing
