#include "spidar/device/string_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "spidar/device/unwrapped_counts.hpp"

namespace spidar::device {

CalibrationUser::CalibrationUser(const strings::DeviceConfig& config, double approach_s)
    : rest_(rest_points(config)), hover_(hovering_hands(rest_)), approach_s_(approach_s) {}

void CalibrationUser::activate(int finger, const Vec3& p_W_target, double t_s) {
  // Start from wherever the finger is meant to be now.
  std::vector<Vec3> now(rest_.size());
  goals(t_s, now);
  finger_ = finger;
  from_ = finger >= 0 && finger < static_cast<int>(now.size())
              ? now[static_cast<std::size_t>(finger)]
              : Vec3::Zero();
  target_ = p_W_target;
  t_active_ = t_s;
}

void CalibrationUser::goals(double t_s, std::span<Vec3> p_W_goal) {
  hover_(t_s, p_W_goal);
  if (finger_ < 0 || finger_ >= static_cast<int>(p_W_goal.size())) return;
  const double u = std::clamp((t_s - t_active_) / approach_s_, 0.0, 1.0);
  const double s = u * u * (3 - 2 * u);  // smoothstep: at rest at both ends
  p_W_goal[static_cast<std::size_t>(finger_)] = from_ + s * (target_ - from_);
}

std::vector<Vec3> calibration_targets(const strings::DeviceConfig& config,
                                      const StringCalibrationParams& params) {
  if (params.jig > 0) return strings::jig_grid(config.p_W_centre, params.jig_spacing_m, params.jig);
  return {config.p_W_centre};
}

namespace {

std::string fmt(const char* format, double a, double b, double c) {
  char buf[160];
  std::snprintf(buf, sizeof buf, format, a, b, c);
  return buf;
}

}  // namespace

Result<std::vector<FingerCalibration>> calibrate_strings(
    Device& device, const strings::DeviceConfig& config, const StringCalibrationParams& params,
    const CalibrationClock& clock, const CalibrationProgress& progress,
    const std::function<void(int, const Vec3&, double)>& on_target) {
  const int strings_n = config.string_count();
  if (device.info().string_count != strings_n)
    return Error{"calibrate strings: device " + device.info().name + " has " +
                 std::to_string(device.info().string_count) + " strings but config " +
                 config.source + " has " + std::to_string(strings_n)};
  for (int f : params.fingers)
    if (f < 0 || f >= static_cast<int>(config.fingers.size()))
      return Error{"calibrate strings: no finger " + std::to_string(f) + " in " + config.source};
  const auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  const std::vector<Vec3> targets = calibration_targets(config, params);
  const std::vector<std::int32_t> commands(static_cast<std::size_t>(strings_n),
                                           config.command_range().min);
  // One unwrapping for the whole run, as the servo cycle does: every sample of every finger is
  // in the same continuous counts.
  UnwrappedCounts counts(strings_n, device.info().counter_bits);
  std::vector<FingerCalibration> out;
  for (int f : params.fingers) {
    const strings::FingerConfig& fc = config.fingers[static_cast<std::size_t>(f)];
    const int first = config.first_string(f), n = fc.geometry.n;
    std::vector<strings::JigSample> samples;
    for (std::size_t k = 0; k < targets.size(); ++k) {
      const Vec3& target = targets[k];
      say(fc.name + ": " +
          (params.jig > 0 ? "place the fingertip cap on jig point " + std::to_string(k + 1) + "/" +
                                std::to_string(targets.size())
                          : std::string("touch the pole tip with the fingertip cap")) +
          " and hold still");
      const double t_step = clock.now_s();
      if (on_target) on_target(f, target, t_step);
      strings::StabilityCheck check(fc, target, params.stability);
      double next_note = t_step + 0.25;
      EncoderReading reading;
      while (!check.ready()) {
        reading.repeats = 0;
        if (auto st = device.read(reading); !st) return Error{"device: " + st.error().message};
        (void)device.write(commands);
        counts.update(reading);
        if (clock.pace) clock.pace();
        const double t = clock.now_s();
        check.update(t, counts.counts(first, n));
        if (t >= next_note) {
          next_note += 0.25;
          const char* state = check.distance_m() > params.stability.near_m ? "not at the target yet"
                              : check.held_s() > 0                         ? "holding"
                                                                           : "moving";
          say(std::string("  ") + state +
              fmt(": %.0f mm away by the present calibration, held %.0f/%.0f ms",
                  check.distance_m() * 1e3, check.held_s() * 1e3, params.stability.hold_s * 1e3));
        }
        if (t - t_step > params.timeout_s)
          return Error{
              fc.name +
              fmt(": the fingertip did not hold still near the target within %.0f s (last: %.1f mm "
                  "away, strings moving %.2f mm)",
                  params.timeout_s, check.distance_m() * 1e3, check.spread_m() * 1e3)};
      }
      samples.push_back({target, check.sample()});
      say(fmt("  sampled after holding %g s", params.stability.hold_s, 0, 0));
    }
    FingerCalibration r;
    r.finger = f;
    if (params.jig > 0) {
      auto fit = strings::fit_multipoint(fc.geometry, samples);
      if (!fit) return Error{fc.name + ": " + fit.error().message};
      for (const auto& sf : *fit) {
        r.channels.push_back(sf.channel);
        r.residual_rms_m.push_back(sf.residual_rms);
      }
    } else {
      const auto& pole = samples.front();
      auto ch = strings::pole_calibrate(fc.geometry, fc.channels, pole.counts, pole.p_WF);
      if (!ch) return Error{fc.name + ": " + ch.error().message};
      r.channels = *ch;
      const auto error_m =
          [&](std::span<const strings::EncoderChannel> c) -> std::optional<double> {
        const auto p_W = strings::fingertip_from_counts(fc, c, pole.counts);
        if (!p_W) return std::nullopt;
        return (*p_W - pole.p_WF).norm();
      };
      r.pole_error_before_m = error_m(fc.channels);
      r.pole_error_after_m = error_m(r.channels);
    }
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace spidar::device
