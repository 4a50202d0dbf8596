// The servo loop ends on time when its thread is starved: pinned at SCHED_FIFO 80 to a CPU that a
// SCHED_FIFO 90 thread holds, it never runs again. Before ServoLoop's monitor ended the loop by the
// wall clock and released the starved thread, wait() and stop() blocked until the hog let go (a
// 4 s device-test ran for ten minutes).
//
// Not a timing assertion on the servo rate, and not flaky: the bound (3 × the run + 5 s) is
// seconds above what the fixed loop needs (max_seconds + kMaxSecondsGrace_s + one stall window,
// then one scheduling of a normal thread on a free CPU), while the unfixed loop waits for the
// hog's own end, 30 s later. The hog cannot outlive the test (it stops at 30 s by itself).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "cpu_hog.hpp"
#include "device_test_support.hpp"
#include "spidar/device/servo_loop.hpp"

namespace spidar::device {
namespace {

using namespace std::chrono_literals;
using testing::spidar8;

constexpr double kHogSeconds = 30.0;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Skips where the test cannot starve anything: one CPU, or no permission for SCHED_FIFO.
#define SPIDAR_STARVE_SERVO_CPU(hog)                                                          \
  if (spidar::test::FifoCpuHog::last_cpu() < 1) GTEST_SKIP() << "needs two CPUs";             \
  spidar::test::FifoCpuHog hog(spidar::test::FifoCpuHog::last_cpu(), 90, kHogSeconds);        \
  if (!hog.holding()) GTEST_SKIP() << "cannot starve the servo thread: " << hog.error()

TEST(ServoLoopStarved, MaxSecondsEndsTheLoopOnTimeWhenItsCpuIsHeld) {
  SPIDAR_STARVE_SERVO_CPU(hog);
  SimulatedSpidar sim(spidar8(), {}, testing::hovering(spidar8()));
  ASSERT_TRUE(sim.open().ok());
  ServoConfig cfg;
  cfg.realtime = true;  // SCHED_FIFO 80 on the last CPU, under the hog's 90
  cfg.max_seconds = 0.5;
  ServoLoop loop(sim, spidar8(), cfg, std::make_shared<ZeroForce>());
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(loop.start().ok());
  loop.wait();
  const double took = seconds_since(t0);
  EXPECT_LT(took, 3 * cfg.max_seconds + 5.0) << "the loop waited for the hog";
  EXPECT_FALSE(loop.running());
  const ServoStats s = loop.stats();
  EXPECT_TRUE(s.realtime_scheduling);
  EXPECT_TRUE(s.released_at_end) << "the servo thread was not starved: the test tested nothing";
  // Starved, the device was put in its safe state by the monitor.
  EXPECT_TRUE(s.faults & kFaultWatchdog) << fault_names(s.faults);
}

// The loop's end by the wall clock (max_seconds + kMaxSecondsGrace_s = 0.55 s) comes before the
// watchdog's first check (4 stall windows = 0.8 s): the end must still latch the stall it saw.
TEST(ServoLoopStarved, ARunShorterThanTheStartUpGraceStillLatchesTheStall) {
  SPIDAR_STARVE_SERVO_CPU(hog);
  SimulatedSpidar sim(spidar8(), {}, testing::hovering(spidar8()));
  ASSERT_TRUE(sim.open().ok());
  ServoConfig cfg;
  cfg.realtime = true;
  cfg.max_seconds = 0.05;
  cfg.stall_limit_s = 0.2;
  ServoLoop loop(sim, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  loop.wait();
  const ServoStats s = loop.stats();
  EXPECT_TRUE(s.released_at_end) << "the servo thread was not starved: the test tested nothing";
  EXPECT_TRUE(s.faults & kFaultWatchdog) << fault_names(s.faults);
}

TEST(ServoLoopStarved, StopReturnsOnTimeWhenItsCpuIsHeld) {
  SPIDAR_STARVE_SERVO_CPU(hog);
  SimulatedSpidar sim(spidar8(), {}, testing::hovering(spidar8()));
  ASSERT_TRUE(sim.open().ok());
  ServoConfig cfg;
  cfg.realtime = true;
  ServoLoop loop(sim, spidar8(), cfg, std::make_shared<ZeroForce>());  // no max_seconds
  ASSERT_TRUE(loop.start().ok());
  std::this_thread::sleep_for(200ms);
  const auto t0 = std::chrono::steady_clock::now();
  loop.stop();
  EXPECT_LT(seconds_since(t0), 5.0) << "stop() waited for the hog";
  EXPECT_FALSE(loop.running());
  EXPECT_TRUE(loop.stats().released_at_end);
}

// What failed one CI run in several (ASan, ctest -j2, 2026-11-28): the servo thread had not yet
// reached its set-up when stop() came (started on the held CPU at normal priority, the other CPU
// busy). The monitor released it once; it then raised its priority, pinned itself to the held CPU
// and was starved until the hog ended. Here the thread is held back deterministically until
// after that first release; the monitor must release it again.
TEST(ServoLoopStarved, StopReturnsOnTimeWhenTheThreadPinsItselfAfterTheRelease) {
  SPIDAR_STARVE_SERVO_CPU(hog);
  SimulatedSpidar sim(spidar8(), {}, testing::hovering(spidar8()));
  ASSERT_TRUE(sim.open().ok());
  std::atomic<bool> stop_called{false};
  ServoConfig cfg;
  cfg.realtime = true;
  // Until well after the stop request and the monitor's first release (one stall window).
  const auto hold = std::chrono::duration<double>(3 * std::max(cfg.stall_limit_s, 1e-3));
  cfg.on_thread_start = [&stop_called, hold] {
    while (!stop_called.load()) std::this_thread::sleep_for(1ms);
    std::this_thread::sleep_for(hold);
  };
  ServoLoop loop(sim, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  std::this_thread::sleep_for(50ms);
  const auto t0 = std::chrono::steady_clock::now();
  stop_called.store(true);
  loop.stop();
  EXPECT_LT(seconds_since(t0), 5.0) << "stop() waited for the hog: the thread was released only once";
  EXPECT_FALSE(loop.running());
  const ServoStats s = loop.stats();
  EXPECT_TRUE(s.realtime_scheduling) << "the thread never went real-time: the test tested nothing";
  EXPECT_TRUE(s.released_at_end);
}

}  // namespace
}  // namespace spidar::device
