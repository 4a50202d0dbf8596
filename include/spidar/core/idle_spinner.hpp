#pragma once
/// Keeps one CPU from halting while it has nothing else to run: a thread pinned to it at
/// SCHED_IDLE that spins (with the CPU's pause hint), always or ahead of a deadline
/// (IdleSpinWindow), until it is destroyed.
///
/// Why: in a VM an idle vCPU halts, and a halted vCPU takes its host hundreds of microseconds to
/// resume, so a 1 kHz servo loop that sleeps between cycles wakes late whenever its CPU went idle
/// (docs/realtime.md). A PM QoS request (CpuLatencyRequest) keeps idle CPUs polling only where a
/// cpuidle driver honours it; this VM has none (idle is a plain HLT). Measured here,
/// `device-test --seconds 5`: jitter p99 462–650 µs quiet without the spinner, 34–38 µs with it;
/// with one core kept busy elsewhere 42–476 µs against 54–186 µs.
///
/// What it costs: the CPU's idle time turns into spinning (power, and the host's time for the
/// vCPU), as `idle=poll` or a PM QoS request of 0 µs does on every CPU. It takes no CPU time from
/// other threads on the machine: SCHED_IDLE runs only when nothing else wants the CPU (weight 3
/// against a nice-0 thread's 1024), a waking normal or real-time thread preempts it at once, and
/// the scheduler counts a CPU running only SCHED_IDLE threads as idle when it places a waking one.
#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <memory>

#include "spidar/core/result.hpp"

namespace spidar::core {

/// When to spin. Without a deadline the spinner spins whenever the CPU is otherwise idle. With one
/// (a loop's next wake-up, which the loop keeps up to date), it sleeps until `lead_ns` before it
/// and spins from then until the deadline has passed and the loop has set the next: the CPU then
/// still goes idle between cycles, where the scheduler's idle balancing pulls waiting threads onto
/// it (a CPU that never idles is left out of that, and a 2-core machine's other threads then wait
/// on one CPU: the demo's frame latency rose from 18.4–19.3 to 20.5–27.5 ms with it spinning
/// always). The spinner's own wake-up may come late too: `lead_ns` should exceed the CPU's wake-up
/// latency, and the wake-ups later than that are what remains.
struct IdleSpinWindow {
  const std::atomic<std::int64_t>* deadline_ns = nullptr;  ///< core::monotonic_ns time; null: spin always
  std::int64_t lead_ns = 500'000;                          ///< spin from this long before it [ns], > 0
};

class IdleSpinner {
 public:
  /// Starts spinning on `cpu` (0-based; −1 = the last online CPU) as `window` says (it must outlive
  /// the spinner). Fails, with nothing left
  /// running, when no thread can be created pinned there. Never waits for the thread to run: it
  /// puts itself at SCHED_IDLE as it starts, and does not spin if that fails (spinning at a normal
  /// priority would take CPU time from real work).
  static Result<std::unique_ptr<IdleSpinner>> start(int cpu = -1, IdleSpinWindow window = {});
  /// Stops the thread and joins it. Bounded even when a real-time thread holds the CPU: if the
  /// spinner has not seen the request within 5 ms it is moved to normal scheduling on every CPU
  /// (release_starved_thread) so that it can end.
  ~IdleSpinner();
  IdleSpinner(const IdleSpinner&) = delete;
  IdleSpinner& operator=(const IdleSpinner&) = delete;

  /// Rounds spun so far (each a few hundred pause hints): it ran.
  std::uint64_t rounds() const { return rounds_.load(std::memory_order_relaxed); }
  /// The CPU it spins on.
  int cpu() const { return cpu_; }

 private:
  IdleSpinner() = default;
  static void* spin(void* self);
  std::atomic<bool> stop_{false};
  std::atomic<bool> ended_{false};
  std::atomic<std::uint64_t> rounds_{0};
  int cpu_ = -1;
  IdleSpinWindow window_;
  bool running_ = false;
  pthread_t thread_{};
};

}  // namespace spidar::core
