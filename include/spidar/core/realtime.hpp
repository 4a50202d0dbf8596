#pragma once
/// Real-time scheduling of the calling thread (Linux): SCHED_FIFO at a priority, and pinning to a
/// CPU. Both need privileges (CAP_SYS_NICE, or rtprio in limits.conf); without them the error
/// says so and the thread keeps running with normal priority.
///
/// Priorities used by spidar-mr (higher runs first): servo loop 80, serial device emulator 70,
/// physics thread 60. Everything else (frame thread, camera, GUI) stays SCHED_OTHER.
#include <pthread.h>

#include <cstdint>

#include "spidar/core/result.hpp"

namespace spidar::core {

/// SCHED_FIFO at `priority` (1..99) for the calling thread. Error names the reason.
Status set_fifo_priority(int priority);

/// The calling thread's share of the CPU among normal (SCHED_OTHER) threads: nice `nice` (−20..19;
/// each step is about 1.25× the share; 10 gets about a tenth of a nice-0 thread's share when both
/// want the CPU). Raising it needs no privilege; below the current value needs CAP_SYS_NICE (or
/// `nice` in limits.conf), and the error says so.
Status set_nice(int nice);

/// A PM QoS request (Linux /dev/cpu_dma_latency) that keeps every CPU out of idle states slower
/// to leave than `max_latency_us` while the object lives: 0 keeps idle CPUs polling instead of
/// halting. In a VM a halted vCPU takes hundreds of microseconds to wake (its host must schedule it
/// again), which a 1 kHz servo loop sees as jitter whenever its CPU went idle between cycles
/// (measured here: device-test jitter p99 83–461 µs without, 27–157 µs with). Opening the file
/// needs root (or write access to it); the error says so and nothing else changes.
class CpuLatencyRequest {
 public:
  static Result<CpuLatencyRequest> open(int max_latency_us = 0);
  CpuLatencyRequest(CpuLatencyRequest&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  CpuLatencyRequest& operator=(CpuLatencyRequest&& other) noexcept;
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;
  /// Closing the file withdraws the request.
  ~CpuLatencyRequest();

 private:
  explicit CpuLatencyRequest(int fd) : fd_(fd) {}
  int fd_ = -1;
};

/// The CPU `cpu` names (0-based; −1 = the last online CPU). Error when it is not online.
Result<int> online_cpu(int cpu);

/// Pins the calling thread to `cpu` (0-based; −1 = the last online CPU). Error names the CPU.
Status pin_to_cpu(int cpu);

/// Takes `cpu` (0-based; −1 = the last online CPU) out of the calling thread's CPU affinity, so
/// that a thread watching another one pinned there (a watchdog) does not share its fate when a
/// higher-priority task holds that CPU. Leaves the affinity as it is, without error, where `cpu`
/// is the only CPU the thread may use. Error names the CPU.
Status avoid_cpu(int cpu);

/// The calling thread's scheduling: its policy (SCHED_OTHER, SCHED_FIFO, ...), its real-time
/// priority (0 for the normal policies) and its nice value (Linux: per thread).
struct ThreadScheduling {
  int policy = 0;
  int priority = 0;
  int nice = 0;
  bool operator==(const ThreadScheduling&) const = default;
};
ThreadScheduling current_scheduling();
/// Gives the calling thread `s` (policy and priority, then nice). Error names what the kernel
/// refused (raising a priority needs CAP_SYS_NICE or an rtprio / nice limit).
Status apply_scheduling(const ThreadScheduling& s);

/// What the kernel counted for the calling thread (getrusage RUSAGE_THREAD): page faults that had
/// to wait for I/O (major: a page read back, e.g. code the kernel dropped from memory) or not
/// (minor), and the times the thread gave up its CPU by waiting (voluntary) or was taken off it
/// (involuntary: preempted, or its time slice ended). All 0 where the call fails.
struct ThreadCounters {
  std::uint64_t major_faults = 0, minor_faults = 0;
  std::uint64_t voluntary_switches = 0, involuntary_switches = 0;
};
ThreadCounters thread_counters();

/// Lets `thread`, which its own scheduling starves, run again so that it can see a stop request
/// and end: SCHED_OTHER (priority 0) on every CPU the calling thread may use. Called from another
/// thread, e.g. for a thread pinned at SCHED_FIFO to a CPU that a higher-priority task holds, or
/// one put at SCHED_IDLE beside busy threads. Both changes are tried; the error names the first
/// that failed.
Status release_starved_thread(pthread_t thread);

}  // namespace spidar::core
