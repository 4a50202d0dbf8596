// SerialDevice::read/write run in the servo thread: on the healthy path they must not allocate.
// Counts operator new calls made by this (the test's) thread only; the emulator thread may
// allocate as it likes.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>


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

TEST(SerialDeviceNoAllocation, ServoReadsThatNeverWait) {
  // reply_wait_s = 0: reads take what is there and repeat the last reading otherwise.
  namespace alloc = ::spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  testing::PtyLink link(24);
  link.start_emulator();
  SerialDeviceConfig c = link.config(24);
  c.reply_wait_s = 0.0;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  std::array<std::int32_t, 24> cmd{};
  int ok = 0;
  alloc::mark_this_thread();
  alloc::start();
  for (int cycle = 0; cycle < 200; ++cycle) {
    for (int i = 0; i < 24; ++i) cmd[i] = (cycle * 17 + i * 100) % 5000 - 200;
    ok += dev.read(r).ok() ? 1 : 0;
    ok += dev.write(cmd).ok() ? 1 : 0;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  alloc::stop();
  EXPECT_EQ(ok, 400);
  EXPECT_EQ(alloc::count(), 0);
  const SerialLinkStats st = dev.link_stats();
  // Every read returned a new reading or repeated one; each new one is a Counts frame taken.
  EXPECT_LE(st.repeated, 200u);
  EXPECT_GE(st.counts_in, 201u - st.repeated);
  EXPECT_EQ(st.timeouts, 0u);
}

}  // namespace
}  // namespace spidar::device
