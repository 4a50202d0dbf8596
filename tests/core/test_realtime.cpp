// Thread scheduling helpers: nice applies to the calling thread only and is range-checked.
#include <gtest/gtest.h>

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <thread>

#include "spidar/core/realtime.hpp"

namespace spidar::core {
namespace {

TEST(Realtime, SetNiceLowersOnlyTheCallingThread) {
  const int before = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  int seen = -100;
  bool ok = false;
  std::thread t([&] {
    ok = set_nice(10).ok();
    seen = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  });
  t.join();
  ASSERT_TRUE(ok);
  EXPECT_EQ(seen, std::max(before, 10));  // raising niceness needs no privilege
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())), before);  // this thread untouched
}

TEST(Realtime, SetNiceRefusesValuesOutsideItsRange) {
  for (int bad : {-21, 20}) {
    const Status s = set_nice(bad);
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_NE(s.error().message.find("-20..19"), std::string::npos) << s.error().message;
  }
}

// Held, the request is in force; where the file cannot be opened (no root) the error names it.
TEST(Realtime, CpuLatencyRequestHoldsTheFileOrSaysWhy) {
  auto r = CpuLatencyRequest::open(0);
  if (!r) {
    EXPECT_NE(r.error().message.find("/dev/cpu_dma_latency"), std::string::npos) << r.error().message;
    return;
  }
  CpuLatencyRequest moved = std::move(r).value();  // moving keeps one open request
  EXPECT_FALSE(CpuLatencyRequest::open(-1).ok());
}

// The counters are the calling thread's own: pages first touched by another thread count there.
TEST(Realtime, ThreadCountersCountTheCallingThreadsPageFaults) {
  constexpr std::size_t kPages = 2048;
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  void* mem = mmap(nullptr, kPages * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(mem, MAP_FAILED);
  const ThreadCounters here_before = thread_counters();
  ThreadCounters before, after;
  std::thread t([&] {
    before = thread_counters();
    auto* bytes = static_cast<volatile unsigned char*>(mem);
    for (std::size_t k = 0; k < kPages; ++k) bytes[k * page] = 1;  // each page's first touch
    after = thread_counters();
  });
  t.join();
  const ThreadCounters here_after = thread_counters();
  munmap(mem, kPages * page);
  EXPECT_GE(after.minor_faults + after.major_faults - before.minor_faults - before.major_faults, kPages / 2)
      << "at most one fault per 2 pages (fault-around does not apply to anonymous memory)";
  EXPECT_LT(here_after.minor_faults - here_before.minor_faults, kPages / 4) << "the other thread's faults";
}


TEST(Realtime, AvoidCpuTakesTheCpuOutOfTheCallingThreadsAffinityOnly) {
  if (sysconf(_SC_NPROCESSORS_ONLN) < 2) GTEST_SKIP() << "needs two CPUs";
  cpu_set_t before, after, caller_after;
  CPU_ZERO(&before);
  CPU_ZERO(&after);
  ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
  if (!CPU_ISSET(0, &before) || CPU_COUNT(&before) < 2) GTEST_SKIP() << "needs CPU 0 and another";
  Status st = Ok{};
  std::thread([&] {
    st = avoid_cpu(0);
    sched_getaffinity(0, sizeof after, &after);
  }).join();
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_FALSE(CPU_ISSET(0, &after));
  EXPECT_EQ(CPU_COUNT(&after), CPU_COUNT(&before) - 1);
  ASSERT_EQ(sched_getaffinity(0, sizeof caller_after, &caller_after), 0);
  EXPECT_TRUE(CPU_EQUAL(&caller_after, &before)) << "it moved the calling test thread too";
}

TEST(Realtime, AvoidCpuLeavesAThreadItsOnlyCpu) {
  cpu_set_t only, after;
  CPU_ZERO(&only);
  CPU_ZERO(&after);
  CPU_SET(0, &only);
  Status st = Ok{};
  std::thread([&] {
    ASSERT_EQ(pthread_setaffinity_np(pthread_self(), sizeof only, &only), 0);
    st = avoid_cpu(0);
    sched_getaffinity(0, sizeof after, &after);
  }).join();
  EXPECT_TRUE(st.ok()) << st.error().message;
  EXPECT_TRUE(CPU_EQUAL(&after, &only));
}

TEST(Realtime, AvoidCpuNamesACpuThatIsNotOnline) {
  const Status st = avoid_cpu(static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)) + 3);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("is not online"), std::string::npos) << st.error().message;
}


TEST(Realtime, ASchedulingReadBackIsWhatWasAppliedToTheCallingThreadOnly) {
  const ThreadScheduling mine = current_scheduling();
  ThreadScheduling seen, after;
  Status st = Ok{};
  std::thread([&] {
    ThreadScheduling want = current_scheduling();
    EXPECT_EQ(want, mine) << "a new thread inherits its creator's scheduling";
    want.nice = std::min(want.nice + 2, 19);  // raising nice needs no privilege
    st = apply_scheduling(want);
    seen = current_scheduling();
    after = want;
  }).join();
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(seen, after);
  EXPECT_EQ(seen.policy, mine.policy);
  EXPECT_EQ(current_scheduling(), mine) << "it changed the calling test thread too";
}

TEST(Realtime, ApplySchedulingNamesAPolicyTheKernelRefuses) {
  Status st = Ok{};
  std::thread([&] { st = apply_scheduling({12345, 0, 0}); }).join();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("policy 12345"), std::string::npos) << st.error().message;
}

}  // namespace
}  // namespace spidar::core
