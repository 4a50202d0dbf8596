#include "spidar/device/reading_checks.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>

#include "spidar/strings/position.hpp"

namespace spidar::device {
namespace {

const char* status_text(std::uint32_t bit) {
  switch (bit) {
    case kFaultDisconnected:
      return "the device reports its encoders or motors disconnected";
    case kFaultReadTimeout:
      return "the device reports it could not read its encoders";
    case kFaultProtocol:
      return "the device refused the request this reading answers";
    case kFaultOverCurrent:
      return "the device reports a motor over its current limit";
    case kFaultEmergencyStop:
      return "the device reports its emergency stop pressed";
    case kFaultWatchdog:
      return "the device reports its heartbeat watchdog tripped (no command or heartbeat reached "
             "it within its timeout) and holds every motor at minimum";
    case kFaultDeadlineMiss:
      return "the device reports a missed deadline";
    case kFaultForceStall:
      return "the device reports a force stall";
    default:
      return "the device reports a fault";
  }
}

const char* finger_name(const strings::DeviceConfig& config, int finger) {
  if (finger < 0 || finger >= static_cast<int>(config.fingers.size())) return "?";
  return config.fingers[static_cast<std::size_t>(finger)].name.c_str();
}

char axis_name(int axis) {
  return axis == 0 ? 'x' : axis == 1 ? 'y' : axis == 2 ? 'z' : '?';
}

}  // namespace

ReadingChecks::ReadingChecks(const strings::DeviceConfig& config, const DeviceInfo& device,
                             const ReadingLimits& limits)
    : config_(config),
      device_clock_(device.device_clock),
      limits_(limits),
      workspace_(device_workspace(config, limits.workspace_margin_m)) {
  for (int f = 0; f < static_cast<int>(config.fingers.size()); ++f) {
    const auto& fc = config.fingers[static_cast<std::size_t>(f)];
    finger_offset_.push_back(static_cast<int>(string_finger_.size()));
    for (int i = 0; i < fc.geometry.n; ++i) {
      string_finger_.push_back(f);
      metres_per_count_.push_back(
          std::abs(fc.channels[static_cast<std::size_t>(i)].metres_per_count));
    }
  }
  previous_counts_.assign(string_finger_.size(), 0);
  inconsistent_in_a_row_.assign(config.fingers.size(), 0);
}

void ReadingChecks::check_status(const EncoderReading& reading, std::uint64_t cycle,
                                 ReadingFindings& out) {
  const std::uint32_t flags = reading.status_flags;
  if (reading.repeats == 0) {
    ++new_readings_;
    if (!(flags & kFaultWatchdog)) watchdog_seen_clear_ = true;
  }
  if (flags == 0) return;
  ReadingFault f;
  f.cycle = cycle;
  f.status_flags = flags;
  const std::uint32_t undefined = flags & ~kDeviceStatusBits;
  if (undefined != 0) {
    f.fault = kFaultProtocol;
    f.after = undefined;
    out.add(f);
    f.after = 0;
  }
  for (int b = 0; b < 8; ++b) {
    const std::uint32_t bit = 1u << b;
    if (!(flags & bit)) continue;
    if (bit == kFaultWatchdog && !watchdog_seen_clear_ &&
        new_readings_ <= kDeviceWatchdogGraceReadings) {
      continue;  // still in the safe state it entered before this run; the first commands end it
    }
    f.fault = bit;
    out.add(f);
  }
}

void ReadingChecks::check_glitch(const EncoderReading& reading, const ServoCycle& measured,
                                 std::uint64_t cycle, ReadingFindings& out) {
  // The time the change took: never less than a period; the longer of the two clocks' steps
  // (an answer that arrived late makes the host's step short, the device's step is the truth).
  double dt = limits_.period_s;
  dt = std::max(dt, static_cast<double>(reading.host_time_ns - previous_host_ns_) * 1e-9);
  if (device_clock_) {
    const double device_dt = static_cast<double>(static_cast<std::uint32_t>(reading.device_time_us -
                                                                            previous_device_us_)) *
                             1e-6;
    if (device_dt <= kMaxBelievedClockStepS) dt = std::max(dt, device_dt);
  }
  const std::span<const std::int64_t> counts = measured.counts();
  const std::size_t n = std::min(counts.size(), previous_counts_.size());
  double worst_ratio = 1.0;
  ReadingFault worst;
  for (std::size_t k = 0; k < n; ++k) {
    const double step_m =
        std::abs(static_cast<double>(counts[k] - previous_counts_[k])) * metres_per_count_[k];
    const double bound_m =
        limits_.max_fingertip_speed_mps * dt + kGlitchSlackCounts * metres_per_count_[k];
    if (!(step_m > bound_m)) continue;
    const double ratio = step_m / bound_m;
    if (ratio <= worst_ratio) continue;
    worst_ratio = ratio;
    worst.fault = kFaultEncoderGlitch;
    worst.cycle = cycle;
    worst.status_flags = reading.status_flags;
    worst.finger = string_finger_[k];
    worst.string = static_cast<int>(k);
    worst.value = step_m;
    worst.bound = bound_m;
    worst.dt_s = dt;
    worst.before = previous_counts_[k];
    worst.after = counts[k];
  }
  if (worst.fault != 0) out.add(worst);
}

void ReadingChecks::check_clock(const EncoderReading& reading, std::uint64_t cycle,
                                ReadingFindings& out) {
  if (reading.device_time_us != previous_device_us_) {
    frozen_readings_ = 0;
    clock_moved_host_ns_ = reading.host_time_ns;
    return;
  }
  if (reading.host_time_ns <= previous_host_ns_) return;  // neither clock moved: nothing to say
  ++frozen_readings_;
  if (frozen_readings_ < limits_.max_frozen_clock_readings) return;
  ReadingFault f;
  f.fault = kFaultFrozenClock;
  f.cycle = cycle;
  f.status_flags = reading.status_flags;
  f.value = frozen_readings_;
  f.bound = limits_.max_frozen_clock_readings;
  f.dt_s = static_cast<double>(reading.host_time_ns - clock_moved_host_ns_) * 1e-9;
  f.after = reading.device_time_us;
  out.add(f);
}

void ReadingChecks::check_measurement(const EncoderReading& reading, const ServoCycle& measured,
                                      const FingertipSample& sample, ReadingFindings& out) {
  const std::uint64_t cycle = sample.cycle;
  if (have_previous_) {
    check_glitch(reading, measured, cycle, out);
    if (device_clock_) check_clock(reading, cycle, out);
  } else {
    clock_moved_host_ns_ = reading.host_time_ns;
  }

  // Workspace: the finger farthest outside.
  ReadingFault outside;
  for (int f = 0; f < sample.finger_count; ++f) {
    const WorkspaceExcess e = workspace_excess(workspace_, sample.p_W[static_cast<std::size_t>(f)]);
    if (e.axis < 0 || (outside.fault != 0 && !(e.distance_m > outside.value))) continue;
    outside.fault = kFaultWorkspace;
    outside.cycle = cycle;
    outside.status_flags = reading.status_flags;
    outside.finger = f;
    outside.value = e.distance_m;
    outside.bound = limits_.workspace_margin_m;
    outside.axis = e.axis;
    outside.lo_m = workspace_.lo_W[e.axis];
    outside.hi_m = workspace_.hi_W[e.axis];
    outside.p_W = sample.p_W[static_cast<std::size_t>(f)];
  }
  if (outside.fault != 0) out.add(outside);

  // Consistency: the finger inconsistent the longest, once over the bound.
  ReadingFault worst;
  const std::span<const double> residuals = measured.residuals();
  const std::span<const double> lengths = measured.lengths();
  const int fingers =
      std::min(sample.finger_count, static_cast<int>(inconsistent_in_a_row_.size()));
  for (int f = 0; f < fingers; ++f) {
    int& run = inconsistent_in_a_row_[static_cast<std::size_t>(f)];
    run = (sample.consistent >> f) & 1u ? 0 : run + 1;
    if (run <= limits_.max_inconsistent_cycles) continue;
    if (worst.fault != 0 && !(run > worst.value)) continue;
    worst.fault = kFaultInconsistent;
    worst.cycle = cycle;
    worst.status_flags = reading.status_flags;
    worst.finger = f;
    worst.string = -1;
    worst.length_m = std::numeric_limits<double>::quiet_NaN();
    worst.value = run;
    worst.bound = limits_.max_inconsistent_cycles;
    worst.residual_m = residuals[static_cast<std::size_t>(f)];
    const auto& fc = config_.fingers[static_cast<std::size_t>(f)];
    for (int i = 0; i < fc.geometry.n; ++i) {
      const int k = measured.string_offset(f) + i;
      const double l = lengths[static_cast<std::size_t>(k)];
      if (!std::isfinite(l) || l < 0.0) {
        worst.string = k;
        worst.length_m = l;
        break;
      }
    }
  }
  if (worst.fault != 0) out.add(worst);

  const std::span<const std::int64_t> counts = measured.counts();
  std::copy_n(counts.begin(), std::min(counts.size(), previous_counts_.size()),
              previous_counts_.begin());
  previous_host_ns_ = reading.host_time_ns;
  previous_device_us_ = reading.device_time_us;
  have_previous_ = true;
}

const char* ReadingChecks::describe(const ReadingFault& f, std::span<char> out) const {
  if (out.empty()) return "";
  const auto cycle = static_cast<unsigned long long>(f.cycle);
  const char* name = finger_name(config_, f.finger);
  const int local = f.string >= 0 && f.finger >= 0
                        ? f.string - finger_offset_[static_cast<std::size_t>(f.finger)]
                        : -1;
  switch (f.fault) {
    case kFaultEncoderGlitch:
      std::snprintf(out.data(), out.size(),
                    "finger %d (%s) string %d (device string %d): length changed by %.4g m "
                    "(counts %" PRId64 " -> %" PRId64
                    ") in %.3f ms; a fingertip at "
                    "max_fingertip_speed_mps %g m/s changes it by at most %.4g m (incl. %g counts "
                    "of noise); cycle %llu",
                    f.finger, name, local, f.string, f.value, f.before, f.after, f.dt_s * 1e3,
                    limits_.max_fingertip_speed_mps, f.bound, kGlitchSlackCounts, cycle);
      break;
    case kFaultWorkspace:
      std::snprintf(out.data(), out.size(),
                    "finger %d (%s) solved at (%.4g, %.4g, %.4g) m: %c outside [%.3f, %.3f] m by "
                    "%.4g m (the fulcrums' box grown by workspace_margin_m %.3f m); cycle %llu",
                    f.finger, name, f.p_W[0], f.p_W[1], f.p_W[2], axis_name(f.axis), f.lo_m, f.hi_m,
                    f.value, f.bound, cycle);
      break;
    case kFaultInconsistent:
      if (f.string >= 0) {
        std::snprintf(out.data(), out.size(),
                      "finger %d (%s): no position for %.0f new readings in a row (bound "
                      "max_inconsistent_cycles %.0f): string %d (device string %d) length %.4g m "
                      "is not a length >= 0; cycle %llu",
                      f.finger, name, f.value, f.bound, local, f.string, f.length_m, cycle);
      } else {
        std::snprintf(out.data(), out.size(),
                      "finger %d (%s): string lengths did not meet in one point for %.0f new "
                      "readings in a row (bound max_inconsistent_cycles %.0f); RMS length residual "
                      "%.3g mm (tolerance %.3g mm); cycle %llu",
                      f.finger, name, f.value, f.bound, f.residual_m * 1e3,
                      strings::PositionSolverParams{}.consistency_tolerance * 1e3, cycle);
      }
      break;
    case kFaultFrozenClock:
      std::snprintf(out.data(), out.size(),
                    "the device clock stayed at %" PRId64
                    " us: it did not advance on %.0f new "
                    "readings in a row (bound max_frozen_clock_readings %.0f) while the host clock "
                    "advanced %.3f ms (the whole device, not one string); cycle %llu",
                    f.after, f.value, f.bound, f.dt_s * 1e3, cycle);
      break;
    default:
      if (f.fault == kFaultProtocol && f.after != 0) {
        std::snprintf(out.data(), out.size(),
                      "the device set status bits 0x%08" PRIx64
                      " that the protocol does not "
                      "define (only bits 0-7; status_flags 0x%08x); cycle %llu",
                      static_cast<std::uint64_t>(f.after), f.status_flags, cycle);
      } else {
        std::snprintf(out.data(), out.size(),
                      "%s (status_flags 0x%08x; the status does not say which finger or string); "
                      "cycle %llu",
                      status_text(f.fault), f.status_flags, cycle);
      }
      break;
  }
  return out.data();
}

}  // namespace spidar::device
