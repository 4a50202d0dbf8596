#pragma once
/// The haptic servo loop: a dedicated thread at a fixed rate (default 1 kHz) that, each cycle,
/// reads the encoders, turns counts into lengths and eight fingertip positions, asks the force
/// source for the forces to display, distributes them into string tensions, and writes motor
/// commands. It publishes timestamped fingertip samples through a lock-free ring.
///
/// Real time: it sleeps to absolute deadlines (clock_nanosleep), asks for SCHED_FIFO and a CPU
/// when permitted (a warning otherwise), and in the cycle allocates nothing, takes no locks and
/// logs nothing.
///
/// Safety (docs/realtime.md, "When a fault latches"): commands are clamped to the device limits.
/// A busy machine degrades the display, it does not stop it: a cycle that wakes or ends more than
/// `deadline_periods` late is counted (`deadline_misses`) and sends what it computed from its own
/// reading (a lag, not a jump in force); forces older than `force_timeout_s` are not displayed (minimum tension)
/// until fresh ones come, counted (`stale_force_cycles`). The safe state latches when safety is
/// at stake: the loop stalled for longer than `stall_limit_s` (the motors held old commands that
/// long: kFaultDeadlineMiss, or kFaultWatchdog from the monitor thread when the servo thread stops
/// cycling), forces stale for longer than `stall_limit_s` (kFaultForceStall), emergency stop, and
/// the device faults below. A device error (disconnect, timeout) puts the device in its safe
/// state and ends the loop with the fault reported.
///
/// Device faults reach the safe state within the cycle their reading arrives (reading_checks.hpp):
/// status bits the device reports (over-current, emergency stop, …) are checked right after the
/// read, before anything is computed; after the positions are solved, a string length that jumps
/// faster than a fingertip can move (kFaultEncoderGlitch), a device clock that stopped
/// (kFaultFrozenClock), a fingertip outside the workspace (kFaultWorkspace) and a finger whose
/// lengths stay inconsistent (kFaultInconsistent). Every latched fault holds the safe state until
/// `reset_faults()`, and has a line of text in `ServoStats::fault_message` saying what, where
/// (finger, string) and the value against its bound, written on the cycle it latched (fault_log.hpp).
///
/// Late readings: a device may return its previous reading again (`EncoderReading::repeats` > 0;
/// the serial backend does when the answer to the last commands has not arrived yet). The loop
/// then runs the cycle on the last counts, as drivers of USB SPIDARs do, counts it, and does not
/// publish a fingertip sample for it (samples are measurements: their times strictly increase).
/// More than `max_repeated_readings` repeats in a row latch kFaultStaleCounts (safe state).
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "spidar/core/seqlock.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/fault_log.hpp"
#include "spidar/device/force_source.hpp"
#include "spidar/device/reading_checks.hpp"
#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device {

struct ServoConfig {
  double rate_hz = 1000.0;
  bool realtime = true;           ///< try SCHED_FIFO (priority 80) and CPU pinning
  int cpu = -1;                   ///< CPU to pin to; -1: the last CPU
  /// With `realtime`: keep the servo's CPU from halting before each cycle (core::IdleSpinner, a
  /// SCHED_IDLE thread spinning on it from idle_spin_lead_s before each deadline). In a VM a
  /// halted vCPU wakes hundreds of microseconds late: `device-test` jitter p99 460–650 µs quiet
  /// without, 25–45 µs with. Off by default: on a 2-core machine that also runs a camera pipeline
  /// it cost the demo's frames 1–2 ms of latency and gained little there (docs/realtime.md);
  /// `device-test` and the haptic scenario turn it on.
  bool idle_spin = false;
  /// How long before each deadline the spinner spins [s]; 0: always (the CPU never idles, which
  /// starves the scheduler's idle balancing: docs/realtime.md). In [0, 1].
  double idle_spin_lead_s = 0.0005;
  /// A cycle that wakes or ends this many periods late counts as a deadline miss; > 0.
  double deadline_periods = 5.0;
  double force_timeout_s = 0.02;  ///< forces older than this are not displayed [s], > 0
  /// A stall this long latches the safe state [s]: the loop late by it (kFaultDeadlineMiss) or no
  /// cycle completed in it (kFaultWatchdog, the monitor thread): the motors held old commands that
  /// long. In (0, 1] s: a device's safety cannot be switched off by a large value.
  double stall_limit_s = 0.1;
  /// Forces stale this long latch kFaultForceStall [s], counted from when they went stale: the
  /// force source is gone. Stale forces are already not displayed (minimum tension) after
  /// force_timeout_s, so nothing pulls on a finger meanwhile and a starved physics thread on a
  /// busy machine degrades the display rather than ending the session. In (0, 10] s.
  double force_lost_s = 1.0;
  /// Consecutive cycles that may run on a repeated (late) device reading; one more trips the
  /// safe state (kFaultStaleCounts). 20 cycles = 5 ms at 4 kHz, 20 ms at 1 kHz.
  int max_repeated_readings = 20;
  /// A solved fingertip farther than this outside the box of the device's fulcrums latches
  /// kFaultWorkspace in that cycle [m], ≥ 0. SPIDAR-8's box is 0.73 × 0.57 × 0.46 m.
  double workspace_margin_m = 0.1;
  /// Consecutive new readings a finger's lengths may fail to meet in one point (or be invalid);
  /// one more latches kFaultInconsistent. ≥ 0. 5 = 5 ms at 1 kHz.
  int max_inconsistent_cycles = 5;
  /// Fastest a fingertip moves [m/s], > 0. A string whose length changes by more than this speed
  /// allows between two readings (plus kGlitchSlackCounts counts) latches kFaultEncoderGlitch.
  /// 10 m/s = 10 mm per period at 1 kHz, 342 SPIDAR-8 counts.
  double max_fingertip_speed_mps = 10.0;
  /// New readings in a row on which the device's clock (`device_time_us`) may not advance while
  /// the host's does; reaching it latches kFaultFrozenClock. ≥ 2. 10 = 10 ms at 1 kHz.
  int max_frozen_clock_readings = 10;
  /// > 0: stop by itself after this long [s]. The servo thread ends itself that long after its
  /// first timed cycle; the monitor thread ends the loop by the wall clock at most
  /// kMaxSecondsGrace_s later whatever the servo thread does (a starved thread that never runs
  /// cannot hold up the end; see ServoLoop::stop).
  double max_seconds = 0.0;
  /// Runs in the servo thread before the first cycle (tests: allocation counters).
  std::function<void()> on_thread_start;
};

struct ServoStats {
  std::uint64_t cycles = 0;
  double seconds = 0;               ///< from first to last cycle
  double rate_hz = 0;               ///< achieved cycle rate
  double jitter_p50_us = 0, jitter_p99_us = 0, jitter_max_us = 0;  ///< |period − nominal|
  double cycle_us_median = 0, cycle_us_p99 = 0, cycle_us_max = 0;  ///< compute time per cycle
  std::uint64_t overruns = 0;       ///< cycles that ended after the next deadline
  std::uint64_t deadline_misses = 0;  ///< cycles more than deadline_periods late
  std::uint64_t stale_force_cycles = 0;  ///< cycles whose forces were older than force_timeout_s
  std::uint64_t repeated_readings = 0;  ///< cycles that ran on a repeated (late) device reading
  std::uint64_t longest_repeat = 0;     ///< longest run of consecutive cycles on repeated readings
  std::uint64_t inconsistent = 0;   ///< finger solves flagged inconsistent
  std::uint32_t faults = 0;         ///< latched Fault bits
  /// What each latched fault was, first fault first: "name: what, which finger/string, value vs
  /// bound; …" (FaultLog::describe). Empty when no fault is latched.
  std::string fault_message;
  bool realtime_scheduling = false; ///< SCHED_FIFO was granted
  bool idle_spin = false;           ///< the servo's CPU was kept from halting (ServoConfig::idle_spin)
  /// The servo thread did not end within a stall window of the stop request (the scheduler starved
  /// it) and was moved to normal scheduling on every CPU so that it could end.
  bool released_at_end = false;
  /// The servo thread's own counts over the run (core::thread_counters): page faults that waited
  /// for I/O, and the times it was taken off its CPU. A late wake with neither rising was the
  /// machine's (a host that stopped the vCPU, a non-preemptible kernel section), not the thread's.
  std::uint64_t major_faults = 0;
  std::uint64_t involuntary_switches = 0;
};

/// How much later than ServoConfig::max_seconds the monitor ends a loop whose servo thread has not
/// ended itself [s] (its first read may take a device handshake).
inline constexpr double kMaxSecondsGrace_s = 0.5;

class ServoLoop {
 public:
  /// The device must already be open. `channels` are the calibrated encoder channels per finger
  /// (default: the config's).
  ServoLoop(Device& device, const strings::DeviceConfig& config, ServoConfig servo,
            std::shared_ptr<ForceSource> force);
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  /// Starts the servo and monitor threads. Errors if already running, the device is closed, or
  /// its link cannot carry the rate (`Device::check_rate`).
  Status start();
  /// Stops the threads (device left in its safe state). Idempotent. Bounded in time even when the
  /// servo thread is starved (pinned at SCHED_FIFO to a CPU a higher-priority task holds, or at
  /// SCHED_IDLE beside busy threads): if it has not ended one stall window (stall_limit_s, at
  /// least 1 ms) after the request, the monitor thread moves it to SCHED_OTHER on every CPU
  /// (core::release_starved_thread) so that it runs, sees the request and ends. Only a machine
  /// whose every CPU is held by higher-priority tasks can still hold it up.
  void stop();
  /// Blocks until the loop ends by itself (max_seconds by the wall clock, a device fault) or
  /// `stop()`.
  void wait();
  bool running() const { return running_.load(std::memory_order_acquire); }

  /// Safe state now, from any thread; latched until `reset_faults()`.
  void emergency_stop();
  /// Clears the loop's latched faults (a backend's own `status().faults` stay) and leaves the
  /// safe state. A condition that still holds (a status bit the device still reports, a finger
  /// still outside the workspace) latches again within a cycle.
  void reset_faults();

  /// Newest fingertip samples, newest first (lock-free; any thread).
  std::size_t newest_samples(FingertipSample* out, std::size_t max) const {
    return ring_.newest(out, max);
  }
  std::uint64_t cycles() const { return cycle_.load(std::memory_order_acquire); }
  std::uint32_t faults() const { return faults_.load(std::memory_order_acquire); }
  /// What each latched fault was (as ServoStats::fault_message); any thread, lock-free.
  std::string fault_message() const { return fault_log_.describe(faults()); }
  /// Statistics; complete once the loop has ended, approximate while it runs.
  ServoStats stats() const;

 private:
  void run();
  void monitor(pthread_t servo_thread);
  /// After a stop request (stop_ set): waits up to `window_ns` for the servo thread to end, then
  /// releases it (see stop()). Monitor thread.
  void end_servo_thread(pthread_t servo_thread, std::int64_t window_ns);
  /// Latches `faults`; for the bits not latched before, records the text (printf `format`).
  /// Returns the newly latched bits. No allocation.
  std::uint32_t latch(std::uint32_t faults, const char* format, ...) noexcept
      __attribute__((format(printf, 3, 4)));
  /// Safe state first, then latches what `findings_` holds, with their texts.
  void latch_findings();

  Device& device_;
  ServoConfig servo_;
  std::shared_ptr<ForceSource> force_;
  std::int64_t period_ns_;

  // Preallocated cycle state.
  ServoCycle cycle_maths_;
  ReadingChecks checks_;
  ReadingFindings findings_;
  std::vector<std::int32_t> commands_;
  FingertipSample sample_;
  ForceFrame force_frame_;

  // Statistics (histograms: 1 µs bins, last bin = overflow).
  static constexpr int kBins = 20000;
  std::vector<std::uint32_t> jitter_hist_, compute_hist_;
  double jitter_max_us_ = 0, compute_max_us_ = 0;
  std::int64_t first_wake_ns_ = 0, last_wake_ns_ = 0;
  std::uint64_t first_timed_cycle_ = 0;  ///< the first cycle is untimed (device handshake)
  std::uint64_t overruns_ = 0;
  std::uint64_t deadline_misses_ = 0;
  std::uint64_t stale_force_cycles_ = 0;
  std::uint64_t repeated_readings_ = 0, longest_repeat_ = 0;
  std::uint64_t major_faults_ = 0, involuntary_switches_ = 0;  ///< the servo thread's, over the run
  FaultLog fault_log_;
  bool realtime_granted_ = false;
  std::atomic<bool> idle_spin_{false};  ///< the servo thread runs a core::IdleSpinner
  std::atomic<std::int64_t> next_deadline_ns_{0};  ///< the servo thread's next wake-up (the spinner's window)
  std::int64_t start_ns_ = 0;  ///< when start() was called (monotonic) [ns]
  std::atomic<bool> released_at_end_{false};

  core::SampleRing<FingertipSample, 1024> ring_;
  std::atomic<bool> running_{false}, stop_{false}, estop_{false};
  std::atomic<std::uint64_t> cycle_{0};
  std::atomic<std::uint32_t> faults_{0};
  std::thread thread_, monitor_thread_;
};

}  // namespace spidar::device
