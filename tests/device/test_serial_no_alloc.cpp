// SerialDevice::read/write run in the servo thread: on the healthy path they must not allocate.
// Counts operator new calls made by this (the test's) thread only; the emulator thread may
// allocate as it likes.
#include <gtest/gtest.h>


#include "allocation_counter.hpp"
#include "pty_link.hpp"

namespace spidar::device {
namespace {

TEST(SerialDeviceNoAllocation, ReadWriteCycles) {
  namespace alloc = ::spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  testing::PtyLink link(24);
  link.start_emulator();
  SerialDevice dev(link.config(24));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  std::array<std::int32_t, 24> cmd{};
  int ok = 0;
  alloc::mark_this_thread();  // the emulator thread may allocate as it likes
  alloc::start();
  for (int cycle = 0; cycle < 200; ++cycle) {
    for (int i = 0; i < 24; ++i) cmd[i] = (cycle * 17 + i * 100) % 5000 - 200;  // some clamped
    ok += dev.write(cmd).ok() ? 1 : 0;
    ok += dev.read(r).ok() ? 1 : 0;
    if (cycle % 10 == 0) ok += dev.read(r).ok() ? 1 : 0;  // polling read (heartbeat)
  }
  alloc::stop();
  EXPECT_EQ(ok, 420);
  EXPECT_EQ(alloc::count(), 0);
}

}  // namespace
}  // namespace spidar::device
