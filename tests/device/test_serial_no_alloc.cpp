// SerialDevice::read/write run in the servo thread: on the healthy path they must not allocate.
// Counts operator new calls made by this (the test's) thread only; the emulator thread may
// allocate as it likes.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "pty_link.hpp"

#if defined(__SANITIZE_ADDRESS__)
#define SPIDAR_COUNT_ALLOCATIONS 0  // the ASan runtime owns operator new
#else
#define SPIDAR_COUNT_ALLOCATIONS 1
#endif

namespace {
thread_local bool t_counting = false;
thread_local long t_allocations = 0;
}  // namespace

#if SPIDAR_COUNT_ALLOCATIONS
void* operator new(std::size_t size) {
  if (t_counting) ++t_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#endif

namespace spidar::device {
namespace {

TEST(SerialDeviceNoAllocation, ReadWriteCycles) {
  if (!SPIDAR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under ASan";
  testing::PtyLink link(24);
  link.start_emulator();
  SerialDevice dev(link.config(24));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  std::array<std::int32_t, 24> cmd{};
  int ok = 0;
  t_allocations = 0;
  t_counting = true;
  for (int cycle = 0; cycle < 200; ++cycle) {
    for (int i = 0; i < 24; ++i) cmd[i] = (cycle * 17 + i * 100) % 5000 - 200;  // some clamped
    ok += dev.write(cmd).ok() ? 1 : 0;
    ok += dev.read(r).ok() ? 1 : 0;
    if (cycle % 10 == 0) ok += dev.read(r).ok() ? 1 : 0;  // polling read (heartbeat)
  }
  t_counting = false;
  EXPECT_EQ(ok, 420);
  EXPECT_EQ(t_allocations, 0);
}

}  // namespace
}  // namespace spidar::device
