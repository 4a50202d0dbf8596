// Thread scheduling helpers: nice applies to the calling thread only and is range-checked.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace spidar::core
