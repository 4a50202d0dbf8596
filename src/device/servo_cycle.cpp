#include "spidar/device/servo_cycle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spidar/strings/device_config.hpp"
#include "spidar/strings/motor.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::device {

// A device config that loads (strings::parse_device_config) fits the samples and the protocol.
static_assert(strings::kMaxConfigFingers == kMaxFingers);
static_assert(strings::kMaxConfigStrings == kMaxDeviceStrings);

ServoCycle::ServoCycle(const strings::DeviceConfig& config, const DeviceInfo& device)
    : config_(config),
      device_(device),
      limits_(config.effective_limits()),
      counts_(std::min(device.string_count, kMaxDeviceStrings), device.counter_bits) {
  if (static_cast<int>(config_.fingers.size()) > kMaxFingers) {
    throw SpidarError("servo: " + std::to_string(config_.fingers.size()) +
                      " fingers in " + config_.source + "; at most " + std::to_string(kMaxFingers));
  }
  if (device_.string_count != config_.string_count()) {
    throw SpidarError("servo: device " + device_.name + " has " +
                      std::to_string(device_.string_count) + " strings but config " +
                      config_.source + " has " + std::to_string(config_.string_count()));
  }
  if (device_.string_count > kMaxDeviceStrings) {
    throw SpidarError("servo: device " + device_.name + " has " + std::to_string(device_.string_count) +
                      " strings; at most " + std::to_string(kMaxDeviceStrings));
  }
  for (int f = 0; f < static_cast<int>(config_.fingers.size()); ++f)
    string_offset_.push_back(config_.first_string(f));
  lengths_.assign(static_cast<std::size_t>(device_.string_count), 0.0);
  residual_.assign(config_.fingers.size(), std::numeric_limits<double>::quiet_NaN());
}

void ServoCycle::measure(const EncoderReading& reading, FingertipSample& sample) {
  sample.t_ns = reading.host_time_ns;
  sample.consistent = 0;
  sample.finger_count = static_cast<int>(config_.fingers.size());
  sample.string_count = string_count();
  counts_.update(reading);
  const auto counts = counts_.counts();
  for (int f = 0; f < sample.finger_count; ++f) {
    const auto& fc = config_.fingers[f];
    const int n = fc.geometry.n, off = string_offset_[f];
    strings::StringVec l(n);
    bool valid = true;
    for (int i = 0; i < n; ++i) {
      l[i] = strings::counts_to_length(fc.channels[i], counts[off + i]);
      lengths_[off + i] = l[i];
      valid = valid && std::isfinite(l[i]) && l[i] >= 0.0;
    }
    residual_[f] = std::numeric_limits<double>::quiet_NaN();
    if (!valid) {  // checked here so the solver's error path (which allocates) is never taken
      ++inconsistent_;
      continue;
    }
    const auto est = strings::solve_position(fc.geometry, std::span<const double>(l.data(), n));
    if (!est.ok()) continue;
    residual_[f] = est->residual;
    if (est->consistent) {
      sample.consistent |= 1u << f;
    } else {
      ++inconsistent_;
    }
    for (int k = 0; k < 3; ++k) sample.p_W[f][k] = est->p_WF[k];
  }
}

void ServoCycle::command(const ForceFrame& force, bool safe, FingertipSample& sample,
                         std::span<std::int32_t> commands) const {
  for (int f = 0; f < sample.finger_count; ++f) {
    const auto& fc = config_.fingers[f];
    const int n = fc.geometry.n, off = string_offset_[f];
    const Vec3 p = fingertip_position(sample, f);
    const Vec3 desired = force.force(f);
    Vec3 shown = Vec3::Zero();
    bool solved = false;
    if (!safe && desired.allFinite() && p.allFinite()) {
      const auto sol = strings::solve_tensions(fc.geometry, p, desired, limits_);
      if (sol.ok()) {
        solved = true;
        shown = sol->f_displayed;
        for (int i = 0; i < n; ++i) {
          commands[off + i] = std::clamp(strings::tension_to_command(config_.motor, sol->t[i]).dac,
                                         device_.command_min, device_.command_max);
          sample.tension[off + i] = sol->t[i];
        }
      }
    }
    if (!solved) {
      for (int i = 0; i < n; ++i) {
        commands[off + i] = device_.command_min;
        sample.tension[off + i] = 0.0;
      }
    }
    for (int i = 0; i < n; ++i) sample.command[off + i] = commands[off + i];
    for (int k = 0; k < 3; ++k) sample.f_W[f][k] = shown[k];
  }
}

void ServoCycle::command_minimum(FingertipSample& sample, std::span<std::int32_t> commands) const {
  std::fill(commands.begin(), commands.end(), device_.command_min);
  sample.string_count = string_count();
  for (int k = 0; k < sample.string_count; ++k) {
    sample.tension[k] = 0.0;
    sample.command[k] = device_.command_min;
  }
  for (int f = 0; f < sample.finger_count; ++f) sample.f_W[f] = {0.0, 0.0, 0.0};
}

}  // namespace spidar::device
