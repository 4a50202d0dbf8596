#include "spidar/core/realtime.hpp"

#include <pthread.h>
#include <fcntl.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <string>

namespace spidar::core {

Status set_fifo_priority(int priority) {
  if (priority < 1 || priority > 99)
    return Error{"SCHED_FIFO priority must be in 1..99, got " + std::to_string(priority)};
  sched_param sp{};
  sp.sched_priority = priority;
  if (const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp); rc != 0) {
    return Error{std::string("SCHED_FIFO ") + std::to_string(priority) + " not permitted (" +
                 std::strerror(rc) + "); grant CAP_SYS_NICE or rtprio in limits.conf"};
  }
  return Ok{};
}

Status set_nice(int nice) {
  if (nice < -20 || nice > 19) return Error{"nice must be in -20..19, got " + std::to_string(nice)};
  // Linux: a thread's nice value is per thread (its tid), not per process.
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) != 0) {
    const int e = errno;
    return Error{"could not set nice " + std::to_string(nice) + " (" + std::strerror(e) + ")" +
                 (e == EPERM || e == EACCES ? "; grant CAP_SYS_NICE or nice in limits.conf" : "")};
  }
  return Ok{};
}

ThreadScheduling current_scheduling() {
  ThreadScheduling s;
  sched_param sp{};
  if (pthread_getschedparam(pthread_self(), &s.policy, &sp) == 0) s.priority = sp.sched_priority;
  errno = 0;
  const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  if (errno == 0) s.nice = nice;
  return s;
}

Status apply_scheduling(const ThreadScheduling& s) {
  sched_param sp{};
  sp.sched_priority = s.priority;
  if (const int rc = pthread_setschedparam(pthread_self(), s.policy, &sp); rc != 0)
    return Error{"could not set scheduling policy " + std::to_string(s.policy) + " priority " +
                 std::to_string(s.priority) + " (" + std::strerror(rc) + ")"};
  // The nice value counts only under the normal policies, but is kept for a return to them.
  return set_nice(s.nice);
}

Result<CpuLatencyRequest> CpuLatencyRequest::open(int max_latency_us) {
  if (max_latency_us < 0) return Error{"CPU latency request: expected >= 0 us, got " + std::to_string(max_latency_us)};
  const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    return Error{std::string("/dev/cpu_dma_latency: ") + std::strerror(e) +
                 (e == EACCES || e == EPERM ? " (needs root or write access)" : "")};
  }
  const std::int32_t value = max_latency_us;
  if (::write(fd, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    const int e = errno;
    ::close(fd);
    return Error{std::string("/dev/cpu_dma_latency: write: ") + std::strerror(e)};
  }
  return CpuLatencyRequest(fd);
}

CpuLatencyRequest& CpuLatencyRequest::operator=(CpuLatencyRequest&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    other.fd_ = -1;
  }
  return *this;
}

CpuLatencyRequest::~CpuLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

Result<int> online_cpu(int cpu) {
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  const int c = cpu >= 0 ? cpu : static_cast<int>(online > 0 ? online - 1 : 0);
  if (online > 0 && c >= online)
    return Error{"CPU " + std::to_string(c) + " is not online (" + std::to_string(online) + " CPUs)"};
  return c;
}

Status pin_to_cpu(int cpu) {
  const auto resolved = online_cpu(cpu);
  if (!resolved) return resolved.error();
  const int c = resolved.value();
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(c, &set);
  if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); rc != 0)
    return Error{"could not pin to CPU " + std::to_string(c) + " (" + std::strerror(rc) + ")"};
  return Ok{};
}

Status avoid_cpu(int cpu) {
  const auto resolved = online_cpu(cpu);
  if (!resolved) return resolved.error();
  const int c = resolved.value();
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0)
    return Error{std::string("could not read the CPU affinity (") + std::strerror(errno) + ")"};
  if (!CPU_ISSET(c, &set) || CPU_COUNT(&set) < 2) return Ok{};
  CPU_CLR(c, &set);
  if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); rc != 0)
    return Error{"could not move off CPU " + std::to_string(c) + " (" + std::strerror(rc) + ")"};
  return Ok{};
}

Status release_starved_thread(pthread_t thread) {
  std::string error;
  sched_param sp{};
  sp.sched_priority = 0;
  if (const int rc = pthread_setschedparam(thread, SCHED_OTHER, &sp); rc != 0)
    error = std::string("could not set SCHED_OTHER (") + std::strerror(rc) + ")";
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    if (const int rc = pthread_setaffinity_np(thread, sizeof(set), &set); rc != 0 && error.empty())
      error = std::string("could not widen its CPU affinity (") + std::strerror(rc) + ")";
  } else if (error.empty()) {
    error = std::string("could not read the CPU affinity (") + std::strerror(errno) + ")";
  }
  if (!error.empty()) return Error{error};
  return Ok{};
}

ThreadCounters thread_counters() {
  rusage u{};
  if (getrusage(RUSAGE_THREAD, &u) != 0) return {};
  auto count = [](long v) { return v > 0 ? static_cast<std::uint64_t>(v) : std::uint64_t{0}; };
  return {count(u.ru_majflt), count(u.ru_minflt), count(u.ru_nvcsw), count(u.ru_nivcsw)};
}

}  // namespace spidar::core
