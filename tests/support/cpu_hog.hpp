#pragma once
// A thread that holds one CPU at SCHED_FIFO, to starve a thread pinned there at a lower priority
// (the servo loop: SCHED_FIFO 80 on the last CPU) for tests that a run still ends on time.
// It spins until destroyed or until `max_s` have passed, so a failing (or hanging) test cannot
// leave it holding the CPU; while it spins, the kernel's real-time throttling
// (sched_rt_runtime_us, 95 % by default) still leaves normal threads 5 % of that CPU.
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <future>
#include <string>
#include <thread>

namespace spidar::test {

class FifoCpuHog {
 public:
  /// Starts the hog on `cpu` at SCHED_FIFO `priority`; returns once it spins there, or failed
  /// to get there (then `error()` says why: usually no CAP_SYS_NICE).
  FifoCpuHog(int cpu, int priority, double max_s) {
    std::promise<std::string> ready;
    auto started = ready.get_future();
    thread_ = std::thread([this, cpu, priority, max_s, &ready] {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(cpu, &set);
      if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set); rc != 0) {
        ready.set_value(std::string("cannot pin to CPU ") + std::to_string(cpu) + ": " + std::strerror(rc));
        return;
      }
      sched_param sp{};
      sp.sched_priority = priority;
      if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp); rc != 0) {
        ready.set_value(std::string("SCHED_FIFO not permitted: ") + std::strerror(rc));
        return;
      }
      ready.set_value("");
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
      while (!stop_.load(std::memory_order_relaxed) && std::chrono::steady_clock::now() < until) {
      }
    });
    error_ = started.get();
  }
  ~FifoCpuHog() {
    stop_.store(true);
    thread_.join();
  }
  FifoCpuHog(const FifoCpuHog&) = delete;
  FifoCpuHog& operator=(const FifoCpuHog&) = delete;

  bool holding() const { return error_.empty(); }
  const std::string& error() const { return error_; }

  /// The CPU the servo loop pins itself to by default (ServoConfig::cpu = −1): the last one.
  static int last_cpu() { return static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)) - 1; }

 private:
  std::atomic<bool> stop_{false};
  std::string error_;
  std::thread thread_;
};

}  // namespace spidar::test
