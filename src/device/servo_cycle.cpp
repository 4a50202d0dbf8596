#include "spidar/device/servo_cycle.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spidar/strings/motor.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::device {

ServoCycle::ServoCycle(const strings::DeviceConfig& config, const DeviceInfo& device)
    : config_(config), device_(device), limits_(config.effective_limits()) {
  if (static_cast<int>(config_.fingers.size()) > kMaxFingers) {
    throw SpidarError("servo: " + std::to_string(config_.fingers.size()) +
                      " fingers in " + config_.source + "; at most " + std::to_string(kMaxFingers));
  }
  if (device_.string_count != config_.string_count()) {
    throw SpidarError("servo: device " + device_.name + " has " +
                      std::to_string(device_.string_count) + " strings but config " +
                      config_.source + " has " + std::to_string(config_.string_count()));
  }
  int offset = 0;
  for (const auto& f : config_.fingers) {
    string_offset_.push_back(offset);
    offset += f.geometry.n;
  }
  unwrap_.assign(offset, strings::CounterUnwrapper(device_.counter_bits));
  counts_.assign(offset, 0);
  lengths_.assign(offset, 0.0);
  residual_.assign(config_.fingers.size(), std::numeric_limits<double>::quiet_NaN());
}

void ServoCycle::measure(const EncoderReading& reading, FingertipSample& sample) {
  sample.t_ns = reading.host_time_ns;
  sample.consistent = 0;
  sample.finger_count = static_cast<int>(config_.fingers.size());
  for (int f = 0; f < sample.finger_count; ++f) {
    const auto& fc = config_.fingers[f];
    const int n = fc.geometry.n, off = string_offset_[f];
    strings::StringVec l(n);
    bool valid = true;
    for (int i = 0; i < n; ++i) {
      const std::int64_t count = unwrap_[off + i].update(reading.counts[off + i]);
      l[i] = strings::counts_to_length(fc.channels[i], count);
      counts_[off + i] = count;
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
    const Vec3 p(sample.p_W[f][0], sample.p_W[f][1], sample.p_W[f][2]);
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
        }
      }
    }
    if (!solved) {
      for (int i = 0; i < n; ++i) commands[off + i] = device_.command_min;
    }
    for (int k = 0; k < 3; ++k) sample.f_W[f][k] = shown[k];
  }
}

}  // namespace spidar::device
