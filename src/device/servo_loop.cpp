#include "spidar/device/servo_loop.hpp"
#include "spidar/core/thread_name.hpp"

#include "spidar/core/idle_spinner.hpp"
#include "spidar/core/realtime.hpp"

#include <optional>
#include <tuple>
#include <utility>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstring>
#include <limits>

#include "spidar/core/clock.hpp"

namespace spidar::device {
namespace {

/// Every latched fault holds the safe state until reset_faults(): the loop's own (deadline,
/// force stall, emergency stop, watchdog, stale counts), the device's status bits and the
/// reading checks (workspace, inconsistent, encoder glitch, frozen clock).
constexpr std::uint32_t kSafeStateFaults = ~std::uint32_t{0};

ReadingLimits reading_limits(const ServoConfig& s) {
  ReadingLimits l;
  l.period_s = 1.0 / std::max(s.rate_hz, 1.0);
  l.workspace_margin_m = s.workspace_margin_m;
  l.max_inconsistent_cycles = s.max_inconsistent_cycles;
  l.max_fingertip_speed_mps = s.max_fingertip_speed_mps;
  l.max_frozen_clock_readings = s.max_frozen_clock_readings;
  return l;
}

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
      checks_(config, device.info(), reading_limits(servo_)),
      commands_(config.string_count(), device.info().command_min),
      jitter_hist_(kBins, 0),
      compute_hist_(kBins, 0) {
  if (!(servo_.idle_spin_lead_s >= 0 && servo_.idle_spin_lead_s <= 1))
    throw SpidarError("ServoLoop: expected idle_spin_lead_s in [0, 1] s, got " +
                      std::to_string(servo_.idle_spin_lead_s));
  if (!(servo_.deadline_periods > 0) || !(servo_.force_timeout_s > 0) ||
      !(servo_.stall_limit_s > 0 && servo_.stall_limit_s <= 1.0) ||
      !(servo_.force_lost_s > 0 && servo_.force_lost_s <= 10.0))
    throw SpidarError("ServoLoop: expected deadline_periods > 0, force_timeout_s > 0 s, "
                      "stall_limit_s in (0, 1] s and force_lost_s in (0, 10] s, got " +
                      std::to_string(servo_.deadline_periods) + ", " + std::to_string(servo_.force_timeout_s) +
                      " s, " + std::to_string(servo_.stall_limit_s) + " s, " +
                      std::to_string(servo_.force_lost_s) + " s");
  if (!force_) throw SpidarError("ServoLoop: no force source");
  if (!(servo_.rate_hz >= 1.0 && servo_.rate_hz <= 100000.0)) {
    throw SpidarError("ServoLoop: rate " + std::to_string(servo_.rate_hz) +
                      " Hz; expected 1 to 100000 Hz");
  }
  if (servo_.max_repeated_readings < 0) {
    throw SpidarError("ServoLoop: max_repeated_readings " +
                      std::to_string(servo_.max_repeated_readings) + "; expected >= 0");
  }
  if (!(std::isfinite(servo_.workspace_margin_m) && servo_.workspace_margin_m >= 0.0)) {
    throw SpidarError("ServoLoop: workspace_margin_m " + std::to_string(servo_.workspace_margin_m) +
                      " m; expected a finite margin >= 0 m");
  }
  if (servo_.max_inconsistent_cycles < 0) {
    throw SpidarError("ServoLoop: max_inconsistent_cycles " +
                      std::to_string(servo_.max_inconsistent_cycles) + "; expected >= 0");
  }
  if (!(std::isfinite(servo_.max_fingertip_speed_mps) && servo_.max_fingertip_speed_mps > 0.0)) {
    throw SpidarError("ServoLoop: max_fingertip_speed_mps " +
                      std::to_string(servo_.max_fingertip_speed_mps) +
                      " m/s; expected a finite speed > 0 m/s");
  }
  if (servo_.max_frozen_clock_readings < 2) {
    throw SpidarError("ServoLoop: max_frozen_clock_readings " +
                      std::to_string(servo_.max_frozen_clock_readings) +
                      "; expected >= 2 (a device clock in µs may read the same twice)");
  }
}

ServoLoop::~ServoLoop() { stop(); }

Status ServoLoop::start() {
  if (running_.load()) return Error{"servo loop already running"};
  if (!device_.status().open) return Error{"servo loop: device " + device_.info().name + " is not open"};
  if (Status budget = device_.check_rate(servo_.rate_hz); !budget) {
    return Error{"servo loop: " + budget.error().message};
  }
  stop_.store(false);
  released_at_end_.store(false);
  start_ns_ = core::monotonic_ns();
  running_.store(true, std::memory_order_release);
  thread_ = std::thread([this] { run(); });
  monitor_thread_ = std::thread([this, h = thread_.native_handle()] { monitor(h); });
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

std::uint32_t ServoLoop::latch(std::uint32_t faults, const char* format, ...) noexcept {
  if ((faults_.load(std::memory_order_acquire) & faults) == faults) return 0;  // nothing new
  const std::uint32_t fresh = faults & ~faults_.fetch_or(faults, std::memory_order_acq_rel);
  if (fresh != 0) {
    std::va_list args;
    va_start(args, format);
    fault_log_.vrecordf(fresh, format, args);
    va_end(args);
  }
  return fresh;
}

void ServoLoop::latch_findings() {
  device_.request_safe_state();
  std::array<char, FaultLog::kTextSize> text;
  for (int i = 0; i < findings_.count; ++i) {
    const ReadingFault& f = findings_.items[static_cast<std::size_t>(i)];
    if (faults_.load(std::memory_order_acquire) & f.fault) continue;  // latched before: no text
    latch(f.fault, "%s", checks_.describe(f, text));
  }
}

void ServoLoop::emergency_stop() {
  estop_.store(true, std::memory_order_release);
  device_.request_safe_state();
  latch(kFaultEmergencyStop, "emergency stop requested through ServoLoop::emergency_stop() at cycle %llu",
        static_cast<unsigned long long>(cycle_.load(std::memory_order_acquire)));
}

void ServoLoop::reset_faults() {
  estop_.store(false, std::memory_order_release);
  faults_.fetch_and(~kSafeStateFaults, std::memory_order_acq_rel);
  device_.clear_safe_state();
}

void ServoLoop::monitor(pthread_t servo_thread) {
  core::set_thread_name("spidar-watchdog");
  // Off the servo's CPU: a task that holds that CPU must not starve the thread that detects it
  // (on CI the watchdog, woken on the held CPU, first ran after the loop's end and latched nothing).
  if (servo_.realtime) {
    if (const Status away = core::avoid_cpu(servo_.cpu); !away.ok())
      spdlog::warn("servo loop: watchdog: {}", away.error().message);
  }
  // Detects a servo thread that stopped cycling (stuck in a read, starved): safe state at once.
  const auto window_ns = std::max<std::int64_t>(core::s_to_ns(servo_.stall_limit_s), 1'000'000);
  // The end by the wall clock, whether the servo thread runs or not.
  const std::int64_t end_ns =
      servo_.max_seconds > 0
          ? start_ns_ + core::s_to_ns(servo_.max_seconds + kMaxSecondsGrace_s)
          : std::numeric_limits<std::int64_t>::max();
  std::uint64_t last = cycle_.load(std::memory_order_acquire);
  std::int64_t last_progress_ns = core::monotonic_ns();  // when `last` was first seen
  std::int64_t next = last_progress_ns + 4 * window_ns;  // grace for start-up
  while (running_.load(std::memory_order_acquire) && !stop_.load(std::memory_order_acquire)) {
    core::sleep_until_ns(std::min({next, end_ns, core::monotonic_ns() + 1'000'000}));
    const std::int64_t woke = core::monotonic_ns();
    const bool at_end = woke >= end_ns;
    // At the end, the stall is checked whenever a window has passed since the last progress seen:
    // a monitor that woke late (its CPU busy), or a run shorter than the start-up grace, must not
    // end the loop without latching the stall it slept through.
    const bool due = woke >= next || (at_end && woke - last_progress_ns >= window_ns);
    if (due) {
      const std::uint64_t now_cycles = cycle_.load(std::memory_order_acquire);
      if (now_cycles == last && running_.load(std::memory_order_acquire)) {
        device_.request_safe_state();
        latch(kFaultWatchdog,
              "monitor: the servo thread completed no cycle for %.3f ms (bound stall_limit_s "
              "%.3f ms, at least 1 ms; 4 times that before the first cycle); stuck in cycle %llu "
              "(a read, the force source or the scheduler)",
              static_cast<double>(core::monotonic_ns() - last_progress_ns) * 1e-6,
              static_cast<double>(window_ns) * 1e-6, static_cast<unsigned long long>(now_cycles));
      }
      if (now_cycles != last) last_progress_ns = core::monotonic_ns();
      last = now_cycles;
      next = core::monotonic_ns() + window_ns;
    }
    if (at_end) {
      stop_.store(true, std::memory_order_release);
      break;
    }
  }
  if (stop_.load(std::memory_order_acquire)) end_servo_thread(servo_thread, window_ns);
}

void ServoLoop::end_servo_thread(pthread_t servo_thread, std::int64_t window_ns) {
  // Released again every window until the thread has ended, not once: a thread that had not yet
  // reached its own set-up when first released (starved on the held CPU at normal priority) goes
  // on to raise its priority and pin itself there, and is starved anew.
  const std::int64_t requested = core::monotonic_ns();
  std::int64_t next_release = requested + window_ns;
  while (running_.load(std::memory_order_acquire)) {
    if (core::monotonic_ns() >= next_release) {
      // Starved (or stuck in a read): let it run anywhere at normal priority. Harmless to a
      // thread that is merely slow, since it is ending anyway.
      const bool first = !released_at_end_.exchange(true, std::memory_order_acq_rel);
      device_.request_safe_state();
      const Status st = core::release_starved_thread(servo_thread);
      if (first || !st.ok()) {
        spdlog::warn("servo loop: the servo thread had not ended {:.0f} ms after the stop request "
                     "(starved by the scheduler?); moved it to normal scheduling on every CPU{}{}",
                     static_cast<double>(core::monotonic_ns() - requested) * 1e-6,
                     st.ok() ? "" : ": ", st.ok() ? "" : st.error().message);
      }
      next_release = core::monotonic_ns() + window_ns;
    }
    core::sleep_until_ns(core::monotonic_ns() + 1'000'000);
  }
}

void ServoLoop::run() {
  core::set_thread_name("spidar-servo");
  if (servo_.on_thread_start) servo_.on_thread_start();
  const core::ThreadCounters counters_at_start = core::thread_counters();
  // The thread's page faults and preemptions since it started (for the report and a stall's message).
  auto counters_since_start = [&counters_at_start] {
    const core::ThreadCounters now = core::thread_counters();
    return std::pair{now.major_faults - std::min(now.major_faults, counters_at_start.major_faults),
                     now.involuntary_switches - std::min(now.involuntary_switches, counters_at_start.involuntary_switches)};
  };
  std::optional<core::CpuLatencyRequest> cpu_latency;
  std::unique_ptr<core::IdleSpinner> idle_spinner;  // declared after: stopped before the request ends
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
    // Idle CPUs poll rather than halt while the loop runs (core::CpuLatencyRequest).
    if (auto qos = core::CpuLatencyRequest::open(0)) {
      cpu_latency.emplace(std::move(qos).value());  // withdrawn when this thread's loop ends
    } else {
      spdlog::warn("servo loop: {}; idle CPUs may sleep deeply between cycles, expect more jitter",
                   qos.error().message);
    }
    // Where no cpuidle driver honours that request (a plain HLT in a VM), the servo's own CPU is
    // kept busy at SCHED_IDLE instead (core::IdleSpinner).
    if (servo_.idle_spin) {
      core::IdleSpinWindow window;
      if (servo_.idle_spin_lead_s > 0) {
        window.deadline_ns = &next_deadline_ns_;
        window.lead_ns = std::max<std::int64_t>(core::s_to_ns(servo_.idle_spin_lead_s), 1);
      }
      next_deadline_ns_.store(core::monotonic_ns() + period_ns_, std::memory_order_release);
      if (auto sp = core::IdleSpinner::start(servo_.cpu, window)) {
        idle_spinner = std::move(sp).value();  // stopped when this thread's loop ends
      } else {
        spdlog::warn("servo loop: {}; its CPU may halt between cycles, expect more jitter", sp.error().message);
      }
    }
  }
  idle_spin_.store(idle_spinner != nullptr, std::memory_order_relaxed);
  if (!(faults_.load() & kSafeStateFaults)) device_.clear_safe_state();

  EncoderReading reading;
  std::int64_t deadline = core::monotonic_ns() + period_ns_;
  std::int64_t prev_wake = 0;
  const std::int64_t late_limit =
      static_cast<std::int64_t>(servo_.deadline_periods * static_cast<double>(period_ns_));
  const std::int64_t stall_limit = core::s_to_ns(servo_.stall_limit_s);
  const std::int64_t force_lost = core::s_to_ns(servo_.force_lost_s);
  std::int64_t stale_since = -1;  ///< host time the forces went stale, −1 while fresh
  while (!stop_.load(std::memory_order_acquire)) {
    next_deadline_ns_.store(deadline, std::memory_order_release);  // the idle spinner's window
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
    sample_.cycle = cycle_.load(std::memory_order_relaxed);
    const auto cycle_no = static_cast<unsigned long long>(sample_.cycle);
    // Woken late: the reading below is fresh, so the cycle runs; it only counts (see the end of
    // the cycle for its commands). A stall long enough to matter latches the safe state.
    if (wake - deadline > stall_limit) {
      device_.request_safe_state();
      const auto [major, preempted] = counters_since_start();
      latch(kFaultDeadlineMiss,
            "cycle %llu woke %.3f ms after its deadline (bound stall_limit_s %.3f ms): the motors "
            "held the previous commands that long (the servo thread so far: %llu page faults "
            "waiting for I/O, taken off its CPU %llu times)",
            cycle_no, static_cast<double>(wake - deadline) * 1e-6, servo_.stall_limit_s * 1e3,
            static_cast<unsigned long long>(major), static_cast<unsigned long long>(preempted));
    }

    reading.repeats = 0;  // backends that never repeat a reading do not touch it
    if (auto st = device_.read(reading); !st.ok()) {
      device_.request_safe_state();
      latch(device_.status().faults | kFaultDisconnected, "cycle %llu: %s", cycle_no,
            st.error().message.c_str());
      break;
    }
    // What the device says about itself comes first: the safe state before anything is computed.
    findings_.clear();
    checks_.check_status(reading, sample_.cycle, findings_);
    if (findings_.faults != 0) latch_findings();
    if (reading.repeats > 0) {
      ++repeated_readings_;
      longest_repeat_ = std::max<std::uint64_t>(longest_repeat_, reading.repeats);
      if (reading.repeats > static_cast<std::uint32_t>(servo_.max_repeated_readings)) {
        device_.request_safe_state();
        latch(kFaultStaleCounts,
              "cycle %llu ran on the same device reading for the %u-th time in a row (bound "
              "max_repeated_readings %d): the device's answers stopped arriving (all strings)",
              cycle_no, reading.repeats, servo_.max_repeated_readings);
      }
    }
    cycle_maths_.measure(reading, sample_);
    if (reading.repeats == 0) {  // a repeated reading was checked when it was new
      findings_.clear();
      checks_.check_measurement(reading, cycle_maths_, sample_, findings_);
      if (findings_.faults != 0) latch_findings();
    }
    force_->forces(sample_, force_frame_);
    // Stale forces are not displayed (the force source fell behind: a starved physics thread);
    // stale for longer than force_lost_s, the source is taken for gone and the safe state latches.
    const bool stale = wake - force_frame_.t_ns > core::s_to_ns(servo_.force_timeout_s);
    if (stale) {
      ++stale_force_cycles_;
      if (stale_since < 0) stale_since = force_frame_.t_ns;
      if (wake - stale_since > force_lost) {
        device_.request_safe_state();
        latch(kFaultForceStall,
              "cycle %llu: the force source's forces are %.3f ms old (not displayed after "
              "force_timeout_s %.3f ms; safe state after force_lost_s %.3f ms; all fingers)",
              cycle_no, static_cast<double>(wake - force_frame_.t_ns) * 1e-6,
              servo_.force_timeout_s * 1e3, servo_.force_lost_s * 1e3);
      }
    } else {
      stale_since = -1;
    }
    sample_.faults = faults_.load(std::memory_order_acquire);
    const bool safe = (sample_.faults & kSafeStateFaults) || estop_.load(std::memory_order_acquire) || stale;
    cycle_maths_.command(force_frame_, safe, sample_, commands_);
    // A cycle woken or ended far past its deadline (a stall in the scheduler, the read or the
    // force source) still sends what it computed (from this cycle's reading: a lag, not a jump
    // in force) and counts; a stall past the stall limit latches the safe state and sends the
    // minimum (the motors held old commands that long).
    if (const std::int64_t late = std::max(wake, core::monotonic_ns()) - deadline;
        cycle_.load(std::memory_order_relaxed) > 0 && late > late_limit) {
      ++deadline_misses_;
      if (late > stall_limit) {
        device_.request_safe_state();
        latch(kFaultDeadlineMiss,
              "cycle %llu ended %.3f ms after its deadline (bound stall_limit_s %.3f ms); its "
              "commands were replaced by the minimum",
              cycle_no, static_cast<double>(late) * 1e-6, servo_.stall_limit_s * 1e3);
        cycle_maths_.command_minimum(sample_, commands_);
      }
    }
    if (auto st = device_.write(commands_); !st.ok()) {
      device_.request_safe_state();
      latch(device_.status().faults | kFaultDisconnected, "cycle %llu: %s", cycle_no,
            st.error().message.c_str());
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
  std::tie(major_faults_, involuntary_switches_) = counters_since_start();
  running_.store(false, std::memory_order_release);
}

ServoStats ServoLoop::stats() const {
  ServoStats s;
  s.cycles = cycle_.load(std::memory_order_acquire);
  s.faults = faults_.load(std::memory_order_acquire);
  s.fault_message = fault_log_.describe(s.faults);  // lock-free: safe while running too
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
  s.deadline_misses = deadline_misses_;
  s.stale_force_cycles = stale_force_cycles_;
  s.repeated_readings = repeated_readings_;
  s.longest_repeat = longest_repeat_;
  s.inconsistent = cycle_maths_.inconsistent();
  s.realtime_scheduling = realtime_granted_;
  s.idle_spin = idle_spin_.load(std::memory_order_relaxed);
  s.released_at_end = released_at_end_.load(std::memory_order_acquire);
  s.major_faults = major_faults_;
  s.involuntary_switches = involuntary_switches_;
  return s;
}

}  // namespace spidar::device
