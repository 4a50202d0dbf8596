#include "spidar/device/servo_loop.hpp"

#include "spidar/core/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "spidar/core/clock.hpp"

namespace spidar::device {
namespace {

constexpr std::uint32_t kSafeStateFaults =
    kFaultDeadlineMiss | kFaultForceStall | kFaultEmergencyStop | kFaultWatchdog |
    kFaultStaleCounts;

/// q-quantile [µs] of a histogram with 1 µs bins.
double percentile(const std::vector<std::uint32_t>& hist, double q) {
  std::uint64_t total = 0;
  for (auto c : hist) total += c;
  if (total == 0) return 0.0;
  const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(total)));
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < hist.size(); ++b) {
    seen += hist[b];
    if (seen >= std::max<std::uint64_t>(rank, 1)) return static_cast<double>(b) + 0.5;
  }
  return static_cast<double>(hist.size());
}

void add_to_hist(std::vector<std::uint32_t>& hist, double us) {
  const auto bin = static_cast<std::size_t>(std::clamp(us, 0.0, static_cast<double>(hist.size() - 1)));
  ++hist[bin];
}

}  // namespace

void PublishedForces::forces(const FingertipSample&, ForceFrame& out) noexcept {
  if (auto f = input_.read()) {
    out = *f;
  } else {
    out.t_ns = 0;  // nothing published yet: stale
    out.f_W = {};
  }
}

ServoLoop::ServoLoop(Device& device, const strings::DeviceConfig& config, ServoConfig servo,
                     std::shared_ptr<ForceSource> force)
    : device_(device),
      servo_(std::move(servo)),
      force_(std::move(force)),
      period_ns_(static_cast<std::int64_t>(1e9 / std::max(servo_.rate_hz, 1.0))),
      cycle_maths_(config, device.info()),
      commands_(config.string_count(), device.info().command_min),
      jitter_hist_(kBins, 0),
      compute_hist_(kBins, 0) {
  if (!force_) throw SpidarError("ServoLoop: no force source");
  if (!(servo_.rate_hz >= 1.0 && servo_.rate_hz <= 100000.0)) {
    throw SpidarError("ServoLoop: rate " + std::to_string(servo_.rate_hz) +
                      " Hz; expected 1 to 100000 Hz");
  }
  if (servo_.max_repeated_readings < 0) {
    throw SpidarError("ServoLoop: max_repeated_readings " +
                      std::to_string(servo_.max_repeated_readings) + "; expected >= 0");
  }
}

ServoLoop::~ServoLoop() { stop(); }

Status ServoLoop::start() {
  if (running_.load()) return Error{"servo loop already running"};
  if (!device_.status().open) return Error{"servo loop: device " + device_.info().name + " is not open"};
  stop_.store(false);
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
  monitor_thread_ = std::thread([this] { monitor(); });
  return Ok{};
}

void ServoLoop::stop() {
  stop_.store(true, std::memory_order_release);
  wait();
  device_.request_safe_state();
}

void ServoLoop::wait() {
  if (thread_.joinable()) thread_.join();
  if (monitor_thread_.joinable()) monitor_thread_.join();
}

void ServoLoop::latch(std::uint32_t fault) { faults_.fetch_or(fault, std::memory_order_acq_rel); }

void ServoLoop::emergency_stop() {
  estop_.store(true, std::memory_order_release);
  device_.request_safe_state();
  latch(kFaultEmergencyStop);
}

void ServoLoop::reset_faults() {
  estop_.store(false, std::memory_order_release);
  faults_.fetch_and(~kSafeStateFaults, std::memory_order_acq_rel);
  device_.clear_safe_state();
}

void ServoLoop::monitor() {
  // Detects a servo thread that stopped cycling (stuck in a read, starved): safe state at once.
  const auto window_ns = std::max<std::int64_t>(
      static_cast<std::int64_t>(servo_.deadline_periods * static_cast<double>(period_ns_)), 1'000'000);
  std::uint64_t last = cycle_.load(std::memory_order_acquire);
  std::int64_t next = core::monotonic_ns() + 4 * window_ns;  // grace for start-up
  while (running_.load(std::memory_order_acquire) && !stop_.load(std::memory_order_acquire)) {
    core::sleep_until_ns(std::min(next, core::monotonic_ns() + 1'000'000));
    if (core::monotonic_ns() < next) continue;
    const std::uint64_t now_cycles = cycle_.load(std::memory_order_acquire);
    if (now_cycles == last && running_.load(std::memory_order_acquire)) {
      device_.request_safe_state();
      latch(kFaultWatchdog);
    }
    last = now_cycles;
    next = core::monotonic_ns() + window_ns;
  }
}

void ServoLoop::run() {
  if (servo_.on_thread_start) servo_.on_thread_start();
  if (servo_.realtime) {
    const Status rt = core::set_fifo_priority(80);
    realtime_granted_ = rt.ok();
    if (!rt.ok()) {
      spdlog::warn("servo loop: {}; running with normal priority, expect more jitter",
                   rt.error().message);
    }
    if (const Status pin = core::pin_to_cpu(servo_.cpu); !pin.ok()) {
      spdlog::warn("servo loop: {}", pin.error().message);
    }
  }
  if (!(faults_.load() & kSafeStateFaults)) device_.clear_safe_state();

  EncoderReading reading;
  std::int64_t deadline = core::monotonic_ns() + period_ns_;
  std::int64_t prev_wake = 0;
  const std::int64_t late_limit =
      static_cast<std::int64_t>(servo_.deadline_periods * static_cast<double>(period_ns_));
  while (!stop_.load(std::memory_order_acquire)) {
    core::sleep_until_ns(deadline);
    const std::int64_t wake = core::monotonic_ns();
    if (prev_wake != 0) {
      const double jitter_us = std::abs(static_cast<double>(wake - prev_wake - period_ns_)) * 1e-3;
      add_to_hist(jitter_hist_, jitter_us);
      jitter_max_us_ = std::max(jitter_max_us_, jitter_us);
    } else {
      first_wake_ns_ = wake;
      first_timed_cycle_ = cycle_.load(std::memory_order_relaxed);
    }
    prev_wake = wake;
    last_wake_ns_ = wake;
    if (wake - deadline > late_limit) {  // the safe state within this cycle
      device_.request_safe_state();
      latch(kFaultDeadlineMiss);
    }

    reading.repeats = 0;  // backends that never repeat a reading do not touch it
    if (auto st = device_.read(reading); !st.ok()) {
      device_.request_safe_state();
      latch(device_.status().faults | kFaultDisconnected);
      fault_message_ = st.error().message;
      break;
    }
    if (reading.repeats > 0) {
      ++repeated_readings_;
      longest_repeat_ = std::max<std::uint64_t>(longest_repeat_, reading.repeats);
      if (reading.repeats > static_cast<std::uint32_t>(servo_.max_repeated_readings)) {
        device_.request_safe_state();
        latch(kFaultStaleCounts);
      }
    }
    sample_.cycle = cycle_.load(std::memory_order_relaxed);
    cycle_maths_.measure(reading, sample_);
    force_->forces(sample_, force_frame_);
    if (wake - force_frame_.t_ns > core::s_to_ns(servo_.force_timeout_s)) {
      device_.request_safe_state();
      latch(kFaultForceStall);
    }
    sample_.faults = faults_.load(std::memory_order_acquire);
    const bool safe = (sample_.faults & kSafeStateFaults) || estop_.load(std::memory_order_acquire);
    cycle_maths_.command(force_frame_, safe, sample_, commands_);
    // A cycle that ran far past its deadline (a stall in the read or the force source) must not
    // send the commands it computed from old data.
    if (cycle_.load(std::memory_order_relaxed) > 0 && core::monotonic_ns() - deadline > late_limit) {
      device_.request_safe_state();
      latch(kFaultDeadlineMiss);
      std::fill(commands_.begin(), commands_.end(), device_.info().command_min);
    }
    if (auto st = device_.write(commands_); !st.ok()) {
      device_.request_safe_state();
      latch(device_.status().faults | kFaultDisconnected);
      fault_message_ = st.error().message;
      break;
    }
    if (reading.repeats == 0) ring_.push(sample_);

    const std::int64_t end = core::monotonic_ns();
    if (prev_wake == wake && cycle_.load(std::memory_order_relaxed) == 0) {
      // The first cycle is untimed: a freshly opened device may answer its first read late
      // (handshake). Deadlines and statistics start from here.
      deadline = end;
      prev_wake = 0;
    }
    const double compute_us = static_cast<double>(end - wake) * 1e-3;
    add_to_hist(compute_hist_, compute_us);
    compute_max_us_ = std::max(compute_max_us_, compute_us);
    deadline += period_ns_;
    if (end > deadline) {
      ++overruns_;
      // Skip the missed cycles instead of bursting to catch up.
      deadline += ((end - deadline) / period_ns_ + 1) * period_ns_;
    }
    cycle_.fetch_add(1, std::memory_order_acq_rel);
    if (servo_.max_seconds > 0 && core::ns_to_s(end - first_wake_ns_) >= servo_.max_seconds) break;
  }
  device_.request_safe_state();
  running_.store(false, std::memory_order_release);
}

ServoStats ServoLoop::stats() const {
  ServoStats s;
  s.cycles = cycle_.load(std::memory_order_acquire);
  s.faults = faults_.load(std::memory_order_acquire);
  if (running_.load(std::memory_order_acquire)) return s;  // histograms belong to the servo thread
  s.seconds = core::ns_to_s(last_wake_ns_ - first_wake_ns_);
  const std::uint64_t periods = s.cycles > first_timed_cycle_ + 1 ? s.cycles - 1 - first_timed_cycle_ : 0;
  s.rate_hz = s.seconds > 0 ? static_cast<double>(periods) / s.seconds : 0;
  s.jitter_p50_us = percentile(jitter_hist_, 0.5);
  s.jitter_p99_us = percentile(jitter_hist_, 0.99);
  s.jitter_max_us = jitter_max_us_;
  s.cycle_us_median = percentile(compute_hist_, 0.5);
  s.cycle_us_p99 = percentile(compute_hist_, 0.99);
  s.cycle_us_max = compute_max_us_;
  s.overruns = overruns_;
  s.repeated_readings = repeated_readings_;
  s.longest_repeat = longest_repeat_;
  s.inconsistent = cycle_maths_.inconsistent();
  s.fault_message = fault_message_;
  s.realtime_scheduling = realtime_granted_;
  return s;
}

}  // namespace spidar::device
