#include "spidar/core/idle_spinner.hpp"
#include "spidar/core/thread_name.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "spidar/core/clock.hpp"
#include "spidar/core/realtime.hpp"

namespace spidar::core {
namespace {

/// The CPU's hint that this is a spin-wait loop (it lets a sibling hyperthread run).
inline void cpu_pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield");
#endif
}

constexpr int kPausesPerRound = 256;
constexpr std::int64_t kStopWaitNs = 5'000'000;
/// The windowed spinner's longest sleep [ns]: how soon it sees a stop request.
constexpr std::int64_t kMaxSleepNs = 1'000'000;

}  // namespace

void* IdleSpinner::spin(void* self_ptr) {
  set_thread_name("spidar-spin");
  auto* self = static_cast<IdleSpinner*>(self_ptr);
  auto round = [self] {
    for (int i = 0; i < kPausesPerRound; ++i) cpu_pause();
    self->rounds_.fetch_add(1, std::memory_order_relaxed);
  };
  // Down to SCHED_IDLE first (lowering needs no privilege; should it fail, it does not spin).
  sched_param sp{};
  sp.sched_priority = 0;
  const bool idle = pthread_setschedparam(pthread_self(), SCHED_IDLE, &sp) == 0;
  const IdleSpinWindow& w = self->window_;
  while (idle && !self->stop_.load(std::memory_order_relaxed)) {
    if (w.deadline_ns != nullptr) {
      // Asleep until the lead before the deadline; then spinning until it has passed and the
      // loop has set the next (or a lead's worth past it, should the loop be held up).
      const std::int64_t d = w.deadline_ns->load(std::memory_order_acquire);
      const std::int64_t now = monotonic_ns();
      if (d - w.lead_ns > now) {
        sleep_until_ns(std::min(d - w.lead_ns, now + kMaxSleepNs));  // a stop is seen within kMaxSleepNs
        continue;
      }
      if (now > d + w.lead_ns) {  // the deadline passed and no next one came: wait for it
        sleep_until_ns(now + std::min(w.lead_ns, kMaxSleepNs));
        continue;
      }
      while (w.deadline_ns->load(std::memory_order_acquire) == d && monotonic_ns() <= d + w.lead_ns &&
             !self->stop_.load(std::memory_order_relaxed))
        round();
      continue;
    }
    round();
  }
  self->ended_.store(true, std::memory_order_release);
  return nullptr;
}

Result<std::unique_ptr<IdleSpinner>> IdleSpinner::start(int cpu, IdleSpinWindow window) {
  const auto resolved = online_cpu(cpu);
  if (!resolved) return Error{"idle spinner: " + resolved.error().message};
  std::unique_ptr<IdleSpinner> s(new IdleSpinner());
  s->cpu_ = resolved.value();
  const std::string where = "idle spinner on CPU " + std::to_string(s->cpu_) + ": ";
  if (window.deadline_ns != nullptr && !(window.lead_ns > 0))
    return Error{where + "the lead before the deadline must be > 0 ns, got " + std::to_string(window.lead_ns)};
  s->window_ = window;
  // Created pinned to its CPU at SCHED_OTHER, not inheriting the caller's scheduling (a caller at
  // SCHED_FIFO would hand it a real-time priority), and not waited for: one starting on a CPU a
  // real-time thread holds would hold up the caller. It goes down to SCHED_IDLE itself (glibc's
  // thread attributes do not take SCHED_IDLE).
  pthread_attr_t attr;
  if (const int rc = pthread_attr_init(&attr); rc != 0) return Error{where + std::strerror(rc)};
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(s->cpu_, &set);
  sched_param sp{};
  sp.sched_priority = 0;
  int rc = pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  if (rc == 0) rc = pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  if (rc == 0) rc = pthread_attr_setschedparam(&attr, &sp);
  if (rc == 0) rc = pthread_attr_setaffinity_np(&attr, sizeof(set), &set);
  if (rc == 0) rc = pthread_create(&s->thread_, &attr, &IdleSpinner::spin, s.get());
  pthread_attr_destroy(&attr);
  if (rc != 0) return Error{where + "could not start a thread pinned there (" + std::strerror(rc) + ")"};
  s->running_ = true;
  return s;
}

IdleSpinner::~IdleSpinner() {
  if (!running_) return;
  stop_.store(true, std::memory_order_relaxed);
  // Sleeping, not yielding: the caller may be a real-time thread pinned to the spinner's CPU,
  // which only gives the CPU up to a SCHED_IDLE thread by blocking.
  const std::int64_t until = monotonic_ns() + kStopWaitNs;
  while (!ended_.load(std::memory_order_acquire) && monotonic_ns() < until) sleep_until_ns(monotonic_ns() + 20'000);
  if (!ended_.load(std::memory_order_acquire)) (void)release_starved_thread(thread_);
  pthread_join(thread_, nullptr);
}

}  // namespace spidar::core
