// Thread scheduling helpers: nice applies to the calling thread only and is range-checked.
#include <gtest/gtest.h>

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

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

}  // namespace
}  // namespace spidar::core
