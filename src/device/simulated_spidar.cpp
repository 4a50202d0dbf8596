#include "spidar/device/simulated_spidar.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

#include "spidar/core/clock.hpp"
#include "spidar/strings/motor.hpp"

namespace spidar::device {

SimulatedSpidar::SimulatedSpidar(const strings::DeviceConfig& config, SimulatedSpidarParams params,
                                 std::shared_ptr<FingertipSource> source)
    : config_(config), params_(params), source_(std::move(source)), rng_(params.seed) {
  if (!source_) throw SpidarError("SimulatedSpidar: no fingertip source");
  info_.name = "simulated " + config.name;
  info_.string_count = config.string_count();
  if (info_.string_count > kMaxDeviceStrings) {
    throw SpidarError("SimulatedSpidar: " + std::to_string(info_.string_count) +
                      " strings; at most " + std::to_string(kMaxDeviceStrings) + " supported");
  }
  info_.counter_bits = config.counter_bits;
  info_.command_min = config.command_range().min;
  info_.command_max = config.command_range().max;
  std::normal_distribution<double> scale(0.0, params.scale_error);
  const int nf = static_cast<int>(config.fingers.size());
  for (int f = 0; f < nf; ++f) {
    const auto& fc = config.fingers[f];
    for (int i = 0; i < fc.geometry.n; ++i) {
      String s{f, fc.geometry.p_WA[i], fc.channels[i]};
      s.truth.metres_per_count *= 1.0 + (params.scale_error > 0 ? scale(rng_) : 0.0);
      // Counters zeroed with the fingertip at the pole (frame centre).
      s.truth.length_at_zero = (s.p_WA - config.p_W_centre).norm();
      strings_.push_back(s);
    }
  }
  x_.assign(nf, config.p_W_centre);
  v_.assign(nf, Vec3::Zero());
  goal_.assign(nf, config.p_W_centre);
  hold_.assign(static_cast<std::size_t>(nf), FingertipHold{});
  force_.assign(nf, Vec3::Zero());
  commands_.assign(strings_.size(), info_.command_min);
  applied_ = commands_;
}

Status SimulatedSpidar::open() {
  t_s_ = 0;
  source_->goals(0.0, goal_);
  take_holds();
  x_ = goal_;
  for (auto& v : v_) v.setZero();
  for (auto& s : strings_) s.tension = strings::command_to_tension(config_.motor, info_.command_min);
  opened_ns_ = last_ns_ = core::monotonic_ns();
  hung_ = false;
  faults_.store(kFaultNone);
  open_ = true;
  return Ok{};
}

void SimulatedSpidar::close() {
  request_safe_state();
  std::fill(applied_.begin(), applied_.end(), info_.command_min);
  open_ = false;
}

DeviceStatus SimulatedSpidar::status() const {
  return {open_, faults_.load(std::memory_order_acquire)};
}

void SimulatedSpidar::step(double dt) {
  const auto& motor = config_.motor;
  const double lag = 1.0 - std::exp(-dt / params_.motor_time_constant);
  // The safe state acts at once, whoever asked for it (the amplifiers' enable line).
  const bool safe = safe_.load(std::memory_order_acquire);
  for (auto& f : force_) f.setZero();
  for (std::size_t k = 0; k < strings_.size(); ++k) {
    String& s = strings_[k];
    const double target =
        strings::command_to_tension(motor, safe ? info_.command_min : applied_[k]);
    s.tension += (target - s.tension) * lag;
    if (s.tension < params_.slack_tension) continue;  // slack: pulls nothing
    const Vec3 d = s.p_WA - x_[s.finger];
    const double len = d.norm();
    if (len > 1e-9) force_[s.finger] += s.tension * d / len;
  }
  for (std::size_t f = 0; f < x_.size(); ++f)
    step_fingertip(params_.impedance, hold_[f], goal_[f], force_[f], dt, x_[f], v_[f]);
}

void SimulatedSpidar::take_holds() {
  if (!source_->holds(hold_)) {
    std::fill(hold_.begin(), hold_.end(), FingertipHold{});
    return;
  }
  for (auto& h : hold_) h = sanitized(h);
}

void SimulatedSpidar::advance(double dt_s) {
  while (dt_s > 0) {
    const double h = std::min(dt_s, params_.max_substep);
    t_s_ += h;
    source_->goals(t_s_, goal_);
    take_holds();
    step(h);
    dt_s -= h;
  }
}

Status SimulatedSpidar::read(EncoderReading& out) {
  if (!open_) return Error{info_.name + ": read while closed"};
  const std::int64_t now = core::monotonic_ns();
  const double since_open = core::ns_to_s(now - opened_ns_);
  if (params_.disconnect_after_s >= 0 && since_open >= params_.disconnect_after_s) {
    faults_.fetch_or(kFaultDisconnected);
    return Error{info_.name + ": disconnected (injected at " +
                 std::to_string(params_.disconnect_after_s) + " s)"};
  }
  if (params_.hang_after_s >= 0 && !hung_ && since_open >= params_.hang_after_s) {
    hung_ = true;  // a stalled USB transfer
    std::this_thread::sleep_for(std::chrono::duration<double>(params_.hang_duration_s));
  }
  // The user's hands move in real time whatever the servo thread does: the simulated device's
  // time is the time since open, so a late read (a stalled servo thread, a busy machine) catches
  // up on the motion it missed and the ground truth never lags the wall clock (the camera films
  // the hands at wall-clock times). Catch-up is bounded (kMaxCatchUp_s of integration per read).
  last_ns_ = core::monotonic_ns();
  constexpr double kMaxCatchUp_s = 10.0;
  const double dt = params_.fixed_step_s > 0 ? params_.fixed_step_s
                                              : core::ns_to_s(last_ns_ - opened_ns_) - t_s_;
  advance(std::clamp(dt, 0.0, kMaxCatchUp_s));

  out.host_time_ns = last_ns_;
  out.device_time_us = static_cast<std::uint32_t>(std::llround(t_s_ * 1e6));
  out.status_flags = faults_.load() | (over_current_.load() ? kFaultOverCurrent : 0u);
  out.string_count = static_cast<int>(strings_.size());
  for (std::size_t k = 0; k < strings_.size(); ++k) {
    const String& s = strings_[k];
    double len = (s.p_WA - x_[s.finger]).norm();
    if (s.tension < params_.slack_tension) {
      len += params_.slack_sag * (1.0 - std::max(0.0, s.tension) / params_.slack_tension);
    }
    std::int64_t count = strings::length_to_counts(s.truth, len);
    if (params_.count_noise > 0) count += std::llround(params_.count_noise * noise_(rng_));
    out.counts[k] = static_cast<std::int32_t>(strings::wrap_counter(count, info_.counter_bits));
  }
  truth_sample_.t_ns = last_ns_;
  truth_sample_.cycle = reads_++;
  truth_sample_.finger_count = static_cast<int>(std::min<std::size_t>(x_.size(), kMaxFingers));
  for (int f = 0; f < truth_sample_.finger_count; ++f) {
    truth_sample_.p_W[f] = {x_[f].x(), x_[f].y(), x_[f].z()};
    truth_sample_.f_W[f] = {force_[f].x(), force_[f].y(), force_[f].z()};
  }
  truth_ring_.push(truth_sample_);
  return Ok{};
}

Status SimulatedSpidar::write(std::span<const std::int32_t> commands) {
  if (!open_) return Error{info_.name + ": write while closed"};
  if (faults_.load() & kFaultDisconnected) return Error{info_.name + ": disconnected"};
  if (commands.size() != commands_.size()) {
    return Error{info_.name + ": expected " + std::to_string(commands_.size()) +
                 " commands, got " + std::to_string(commands.size())};
  }
  const bool safe = safe_.load(std::memory_order_acquire);
  for (std::size_t k = 0; k < commands.size(); ++k) {
    commands_[k] = commands[k];
    applied_[k] = safe ? info_.command_min
                       : std::clamp(commands[k], info_.command_min, info_.command_max);
  }
  return Ok{};
}

SimulatedTruth SimulatedSpidar::truth() const {
  SimulatedTruth t;
  t.t_s = t_s_;
  t.p_W_fingertip = x_;
  t.f_W_strings = force_;
  for (const auto& s : strings_) {
    t.tension.push_back(s.tension);
    t.slack.push_back(s.tension < params_.slack_tension);
  }
  return t;
}

}  // namespace spidar::device
