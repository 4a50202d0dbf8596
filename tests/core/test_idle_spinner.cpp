// core::IdleSpinner: a thread at SCHED_IDLE pinned to the CPU asked for, seen from outside the
// class through /proc and the scheduler's own calls, gone when the spinner is; a CPU that does not
// exist is refused with nothing left running; the stop is bounded when a real-time thread holds
// the spinner's CPU.
#include <gtest/gtest.h>

#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "idle_threads.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/idle_spinner.hpp"
#include "spidar/core/realtime.hpp"

namespace spidar::core {
namespace {

/// Waits (at most a minute: only a spinner that never runs reaches it) until it has spun.
bool spun(const IdleSpinner& s) {
  const std::int64_t until = monotonic_ns() + 60'000'000'000;
  while (s.rounds() == 0 && monotonic_ns() < until) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return s.rounds() > 0;
}

TEST(IdleSpinner, SpinsAtSchedIdlePinnedToItsCpuUntilDestroyed) {
  ASSERT_TRUE(test::no_idle_thread_within());
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  for (const int asked : {-1, 0}) {
    auto started = IdleSpinner::start(asked);
    ASSERT_TRUE(started.ok()) << started.error().message;
    std::unique_ptr<IdleSpinner> s = std::move(started).value();
    const int cpu = asked >= 0 ? asked : static_cast<int>(online - 1);
    EXPECT_EQ(s->cpu(), cpu);
    EXPECT_TRUE(spun(*s));
    const std::vector<pid_t> idle = test::idle_threads();
    ASSERT_EQ(idle.size(), 1u);
    cpu_set_t set;
    CPU_ZERO(&set);
    ASSERT_EQ(sched_getaffinity(idle[0], sizeof(set), &set), 0);
    EXPECT_EQ(CPU_COUNT(&set), 1);
    EXPECT_TRUE(CPU_ISSET(cpu, &set));
    s.reset();
    EXPECT_TRUE(test::no_idle_thread_within()) << "the spinner's thread outlived it";
  }
}

TEST(IdleSpinner, ACpuThatDoesNotExistIsRefusedWithNothingRunning) {
  const auto s = IdleSpinner::start(4095);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("CPU 4095"), std::string::npos) << s.error().message;
  EXPECT_TRUE(test::no_idle_thread_within());  // an earlier test's spinner may still be leaving
}

/// Waits (at most a minute) until the spinner has stopped spinning: no round in 30 ms. A spinner
/// starved in the middle of a round may finish it later.
bool comes_to_rest(const IdleSpinner& s) {
  for (const std::int64_t until = monotonic_ns() + 60'000'000'000; monotonic_ns() < until;) {
    const std::uint64_t before = s.rounds();
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    if (s.rounds() == before) return true;
  }
  return false;
}

// With a deadline it sleeps until the lead before it and spins from then until the loop sets the
// next deadline, or until the deadline has passed by the lead. The lead here is a minute long, so
// that a spinner starved by other processes (SCHED_IDLE runs last) still gets its turn inside it.
TEST(IdleSpinner, WithADeadlineSpinsOnlyFromItsLead) {
  const std::int64_t lead = 60'000'000'000;
  std::atomic<std::int64_t> deadline{monotonic_ns() + 3'600'000'000'000};  // an hour away
  auto started = IdleSpinner::start(-1, {&deadline, lead});
  ASSERT_TRUE(started.ok()) << started.error().message;
  std::unique_ptr<IdleSpinner> s = std::move(started).value();
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(s->rounds(), 0u);  // asleep: the lead has not begun
  // The lead begins 20 ms from now.
  std::int64_t d = monotonic_ns() + lead + 20'000'000;
  deadline.store(d);
  ASSERT_TRUE(spun(*s));
  EXPECT_GE(monotonic_ns(), d - lead);  // it spun only once the lead had begun
  // The loop woke and set its next deadline, an hour away: the spinner sleeps again.
  deadline.store(monotonic_ns() + 3'600'000'000'000);
  EXPECT_TRUE(comes_to_rest(*s));
  // Spinning again, then a deadline that has passed by more than the lead with no next one (a
  // loop held up): it sleeps.
  d = monotonic_ns() + lead;
  const std::uint64_t rested = s->rounds();
  deadline.store(d);
  for (const std::int64_t until = monotonic_ns() + 60'000'000'000; s->rounds() == rested && monotonic_ns() < until;)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GT(s->rounds(), rested);
  deadline.store(monotonic_ns() - 3 * lead);
  EXPECT_TRUE(comes_to_rest(*s));
  // A lead that is not positive is refused.
  const auto bad = IdleSpinner::start(-1, {&deadline, 0});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("lead"), std::string::npos) << bad.error().message;
}

// A SCHED_FIFO thread holding the spinner's CPU starves it; its destructor still returns, by
// moving it to normal scheduling on every CPU. Needs SCHED_FIFO (root or rtprio).
TEST(IdleSpinner, StopsWhenARealTimeThreadHoldsItsCpu) {
  auto started = IdleSpinner::start(-1);
  ASSERT_TRUE(started.ok()) << started.error().message;
  std::unique_ptr<IdleSpinner> s = std::move(started).value();
  ASSERT_TRUE(spun(*s));
  const int cpu = s->cpu();
  std::atomic<bool> hog_on{false}, hog_stop{false};
  std::atomic<int> hog_state{0};  // 1 running at SCHED_FIFO on the CPU, −1 not permitted
  std::thread hog([&] {
    if (!pin_to_cpu(cpu).ok() || !set_fifo_priority(90).ok()) {
      hog_state = -1;
      return;
    }
    hog_state = 1;
    while (!hog_stop.load(std::memory_order_relaxed)) hog_on.store(true, std::memory_order_relaxed);
  });
  while (hog_state.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (hog_state.load() < 0) {
    hog.join();
    GTEST_SKIP() << "SCHED_FIFO not permitted here";
  }
  s.reset();  // returns: the spinner was released from its CPU
  hog_stop = true;
  hog.join();
  EXPECT_TRUE(hog_on.load());
  EXPECT_TRUE(test::no_idle_thread_within());
}

}  // namespace
}  // namespace spidar::core
