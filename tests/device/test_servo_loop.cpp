#include <gtest/gtest.h>

#include <sched.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <random>
#include <thread>

#include "allocation_counter.hpp"
#include "idle_threads.hpp"
#include "named_thread.hpp"
#include "device_test_support.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/servo_loop.hpp"

namespace spidar::device {
namespace {

using namespace std::chrono_literals;
using testing::spidar8;

struct Rig {
  explicit Rig(SimulatedSpidarParams params = {}) : sim(spidar8(), params, testing::hovering(spidar8())), rec(sim) {
    EXPECT_TRUE(sim.open().ok());
  }
  SimulatedSpidar sim;
  testing::RecordingDevice rec;
};

void wait_for_cycles(const ServoLoop& loop, std::uint64_t n) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (loop.cycles() < n && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(1ms);
}

TEST(ServoLoop, RunsAndKeepsOrderedStatistics) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  // Not a timing test: a loaded machine (or a sanitizer) may wake the thread late; the deadline
  // watchdog has its own tests. It runs for a number of cycles, not for a time.
  cfg.deadline_periods = 1000;
  cfg.stall_limit_s = 1.0;
  cfg.idle_spin = true;
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<ZeroForce>());
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 150);
  loop.stop();
  const double ran_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto s = loop.stats();
  EXPECT_EQ(s.faults, 0u) << fault_names(s.faults) << " " << s.fault_message;
  EXPECT_GE(s.cycles, 150u);
  // Never faster than its rate (an upper bound, which a slow machine cannot break): at most one
  // cycle per period of the time it ran, plus the untimed first cycle and edges.
  EXPECT_LE(static_cast<double>(s.cycles), ran_s * cfg.rate_hz + 4.0);
  EXPECT_EQ(static_cast<std::uint64_t>(rig.rec.writes()), s.cycles);
  EXPECT_GT(s.rate_hz, 0.0);
  EXPECT_LE(s.jitter_p50_us, s.jitter_p99_us);
  EXPECT_LE(s.jitter_p99_us, s.jitter_max_us + 1.0);
  EXPECT_LE(s.cycle_us_median, s.cycle_us_p99);
  EXPECT_LE(s.cycle_us_p99, s.cycle_us_max + 1.0);
  EXPECT_GT(s.cycle_us_max, 0.0);
  // Its CPU kept from halting while it ran (core::IdleSpinner; SCHED_IDLE needs no privilege),
  // and the spinner gone with the loop.
  EXPECT_TRUE(s.idle_spin);
  EXPECT_TRUE(test::no_idle_thread_within()) << "the idle spinner outlived the loop";

  // The ring holds the newest samples, newest first, in cycle and time order.
  FingertipSample samples[64];
  const std::size_t n = loop.newest_samples(samples, 64);
  ASSERT_EQ(n, 64u);
  for (std::size_t k = 1; k < n; ++k) {
    EXPECT_EQ(samples[k - 1].cycle, samples[k].cycle + 1);
    EXPECT_GT(samples[k - 1].t_ns, samples[k].t_ns);
  }
  EXPECT_EQ(samples[0].cycle + 1, s.cycles);
  EXPECT_EQ(samples[0].finger_count, 8);
  EXPECT_EQ(samples[0].consistent, 0xFFu);
  // Zero desired force: every motor at its minimum command.
  EXPECT_EQ(rig.rec.min_command(), rig.sim.info().command_min);
  EXPECT_EQ(rig.rec.max_command(), rig.sim.info().command_min);
}

TEST(ServoLoop, PositionsTrackTheSimulatedFingertips) {
  SimulatedSpidarParams params;
  params.fixed_step_s = 1e-3;
  Rig rig(params);
  ServoConfig cfg;
  cfg.max_seconds = 0.2;
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  loop.wait();
  FingertipSample s;
  ASSERT_EQ(loop.newest_samples(&s, 1), 1u);
  const auto truth = rig.sim.truth();
  for (int f = 0; f < 8; ++f) {
    const Vec3 p(s.p_W[f][0], s.p_W[f][1], s.p_W[f][2]);
    EXPECT_LT((p - truth.p_W_fingertip[f]).norm(), 3e-4) << f;
  }
}

TEST(ServoLoop, CycleBodyDoesNotAllocate) {
  namespace alloc = spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 2000;
  cfg.deadline_periods = 1000;  // allocation, not timing: a late wake-up must not stop the forces
  cfg.stall_limit_s = 1.0;
  cfg.on_thread_start = [] { alloc::mark_this_thread(); };
  // A force source that asks for real forces, so tensions and commands vary.
  struct Pushing final : ForceSource {
    void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
      out.t_ns = in.t_ns;
      for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(1.0 + 0.1 * f, -2.0, 3.0 * static_cast<double>(in.cycle % 7) / 7.0));
    }
  };
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<Pushing>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 50);
  alloc::start();
  const auto start = loop.cycles();
  wait_for_cycles(loop, start + 1000);
  alloc::stop();
  loop.stop();
  EXPECT_GE(loop.cycles(), start + 1000);
  EXPECT_EQ(alloc::count(), 0);
  EXPECT_GT(rig.rec.max_command(), rig.sim.info().command_min)  // forces were displayed
      << fault_names(loop.faults()) << ": " << loop.fault_message();
}

TEST(ServoLoop, CommandsNeverLeaveTheMotorLimitsWhateverTheForces) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 2000;
  // A stall of a loaded machine that latched the safe state early would leave every command at
  // its minimum, and the saturation below unseen: the watchdog has its own tests.
  cfg.stall_limit_s = 1.0;
  struct Wild final : ForceSource {
    std::mt19937_64 rng{3};
    void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
      std::uniform_real_distribution<double> u(-1e6, 1e6);
      out.t_ns = in.t_ns;
      for (int f = 0; f < 8; ++f) {
        Vec3 v(u(rng), u(rng), u(rng));
        if (in.cycle % 11 == 0) v.x() = std::numeric_limits<double>::quiet_NaN();
        if (in.cycle % 13 == 0) v.y() = std::numeric_limits<double>::infinity();
        out.set_force(f, v * (in.cycle % 3 == 0 ? 1e-6 : 1.0));
      }
    }
  };
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<Wild>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 1500);
  loop.stop();
  EXPECT_GE(rig.rec.min_command(), rig.sim.info().command_min);
  EXPECT_LE(rig.rec.max_command(), rig.sim.info().command_max);
  EXPECT_EQ(rig.rec.max_command(), rig.sim.info().command_max)  // saturated, not wrapped
      << fault_names(loop.faults()) << ": " << loop.fault_message();
  // Wild forces are not a fault (a loaded machine may still make a cycle late).
  EXPECT_EQ(loop.faults() & ~(kFaultDeadlineMiss | kFaultWatchdog), 0u) << fault_names(loop.faults());
}

/// A force source whose forces stop updating after cycle `freeze_at` and, if `thaw_at` > 0,
/// update again from that cycle on.
struct Stalling final : ForceSource {
  std::uint64_t freeze_at = 100, thaw_at = 0;
  std::int64_t frozen = 0;
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
    if (in.cycle < freeze_at || (thaw_at > 0 && in.cycle >= thaw_at)) frozen = in.t_ns;
    out.t_ns = frozen;
    for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(0, 0, 2.0));
  }
};

// Stale forces are not displayed from the first stale cycle on; the safe state latches only once
// they have been stale for force_lost_s (docs/realtime.md, "When a fault latches").
TEST(ServoLoop, StaleForcesAreNotDisplayedAndLatchAfterTheForceLostLimit) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.force_timeout_s = 0.005;
  cfg.force_lost_s = 0.05;
  cfg.deadline_periods = 1000;  // about the forces' age, not the scheduler
  auto source = std::make_shared<Stalling>();
  ServoLoop loop(rig.rec, spidar8(), cfg, source);
  ASSERT_TRUE(loop.start().ok());
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!(loop.faults() & kFaultForceStall) && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(1ms);
  wait_for_cycles(loop, loop.cycles() + 5);
  loop.stop();
  ASSERT_TRUE(loop.faults() & kFaultForceStall);
  FingertipSample samples[1024];
  const std::size_t n = loop.newest_samples(samples, 1024);
  // The stall began at the last fresh sample (cycle 99): forces after force_timeout_s are zero,
  // and the fault latched no earlier than stall_limit_s after the stall (sample times, not
  // wall-clock assertions).
  std::int64_t t_fresh = -1, t_fault = -1;
  for (std::size_t k = 0; k < n; ++k) {
    if (samples[k].cycle == source->freeze_at - 1) t_fresh = samples[k].t_ns;
  }
  ASSERT_GE(t_fresh, 0) << "the ring no longer holds cycle 99";
  for (std::size_t k = n; k-- > 0;) {
    const FingertipSample& sk = samples[k];
    if (t_fault < 0 && (sk.faults & kFaultForceStall)) t_fault = sk.t_ns;
    if (sk.t_ns - t_fresh > core::s_to_ns(cfg.force_timeout_s) + 2'000'000) {
      for (int f = 0; f < 8; ++f) EXPECT_EQ(sk.f_W[f][2], 0.0) << "cycle " << sk.cycle;
    }
  }
  ASSERT_GE(t_fault, 0);
  EXPECT_GE(t_fault - t_fresh, core::s_to_ns(cfg.force_lost_s));
  EXPECT_GE(loop.stats().stale_force_cycles, 1u);
  EXPECT_GE(rig.rec.safe_requests(), 1);
  EXPECT_TRUE(loop.stats().fault_message.find("force_stall: cycle ") != std::string::npos)
      << loop.stats().fault_message;
}

// Forces stale for less than the stall limit: not displayed meanwhile, displayed again when
// fresh, no fault. A busy machine degrades the display; it does not stop it.
TEST(ServoLoop, BrieflyStaleForcesRecoverWithoutAFault) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.force_timeout_s = 0.005;
  cfg.stall_limit_s = 1.0;  // far longer than the stall below, even on a loaded machine
  cfg.deadline_periods = 1000;
  auto source = std::make_shared<Stalling>();
  source->thaw_at = 130;  // 30 cycles stale
  ServoLoop loop(rig.rec, spidar8(), cfg, source);
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 200);
  loop.stop();
  EXPECT_EQ(loop.faults(), 0u) << fault_names(loop.faults()) << ": " << loop.fault_message();
  EXPECT_GE(loop.stats().stale_force_cycles, 1u);
  FingertipSample samples[1024];
  const std::size_t n = loop.newest_samples(samples, 1024);
  bool shown_after = false;
  for (std::size_t k = 0; k < n; ++k)
    if (samples[k].cycle >= 140 && samples[k].f_W[0][2] != 0.0) shown_after = true;
  EXPECT_TRUE(shown_after) << "forces are displayed again once fresh";
}

/// A force source that sleeps `stall` in cycle 50 (a stall inside the cycle).
struct Slow final : ForceSource {
  std::chrono::milliseconds stall{20};
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
    if (in.cycle == 50) std::this_thread::sleep_for(stall);
    out.t_ns = core::monotonic_ns();
    for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(0, 0, 1.0));
  }
};

// A cycle that ends far past its deadline counts, and the display goes on: no fault, no gap.
TEST(ServoLoop, MissedDeadlineIsCountedWithoutAFault) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.deadline_periods = 5;
  cfg.stall_limit_s = 1.0;  // the 20 ms stall is far below it, even on a loaded machine
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<Slow>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 80);
  loop.stop();
  EXPECT_FALSE(loop.faults() & kFaultDeadlineMiss) << fault_names(loop.faults());
  const auto s = loop.stats();
  EXPECT_GE(s.deadline_misses, 1u);
  EXPECT_GE(s.overruns, 1u);
  EXPECT_GE(s.jitter_max_us, 15000.0);
  FingertipSample samples[1024];
  const std::size_t n = loop.newest_samples(samples, 1024);
  for (std::size_t k = 0; k < n; ++k) {
    if (samples[k].cycle >= 50) {
      EXPECT_NE(samples[k].f_W[0][2], 0.0) << "cycle " << samples[k].cycle;
    }
  }
}

// A stall past the stall limit latches the safe state (the motors held old commands that long).
TEST(ServoLoop, StallPastTheLimitTripsTheSafeState) {
  Rig rig;
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.deadline_periods = 5;
  cfg.stall_limit_s = 0.02;
  auto slow = std::make_shared<Slow>();
  slow->stall = std::chrono::milliseconds(60);
  ServoLoop loop(rig.rec, spidar8(), cfg, slow);
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 80);
  loop.stop();
  EXPECT_TRUE(loop.faults() & kFaultDeadlineMiss) << fault_names(loop.faults());
  const auto s = loop.stats();
  EXPECT_NE(s.fault_message.find("deadline_miss: cycle "), std::string::npos) << s.fault_message;
  EXPECT_NE(s.fault_message.find("stall_limit_s"), std::string::npos) << s.fault_message;
  EXPECT_GE(rig.rec.safe_requests(), 1);
  // Latched: cleared only on request.
  loop.reset_faults();
  EXPECT_FALSE(loop.faults() & kFaultDeadlineMiss);
}

TEST(ServoLoop, MonitorCatchesAServoThreadStuckInARead) {
  SimulatedSpidarParams params;
  params.hang_after_s = 0.1;
  params.hang_duration_s = 0.2;
  Rig rig(params);
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.stall_limit_s = 0.02;  // the monitor's window (4 times that before the first cycle)
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  // The read hangs from 0.1 s to 0.3 s; the fault stays latched after it, so a monitor woken late
  // (a loaded machine, a sanitizer) is waited for, not raced.
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!(loop.faults() & kFaultWatchdog) && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(1ms);
  EXPECT_TRUE(loop.faults() & kFaultWatchdog) << fault_names(loop.faults());
  EXPECT_GE(rig.rec.safe_requests(), 1);
  loop.stop();
  EXPECT_NE(loop.fault_message().find("watchdog: monitor: the servo thread completed no cycle"),
            std::string::npos)
      << loop.fault_message();
}

// The watchdog must not share the CPU the servo pins itself to: a task holding that CPU starves
// both, and the stall went unlatched (a CI run, ASan, 2026-11-29: the watchdog first ran after the
// loop's end). Deterministic: it checks where the watchdog may run, not when it ran.
TEST(ServoLoop, TheWatchdogRunsOffTheServosCpu) {
  if (sysconf(_SC_NPROCESSORS_ONLN) < 2) GTEST_SKIP() << "needs two CPUs";
  const int servo_cpu = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)) - 1;
  cpu_set_t mine;
  CPU_ZERO(&mine);
  ASSERT_EQ(sched_getaffinity(0, sizeof mine, &mine), 0);
  if (!CPU_ISSET(servo_cpu, &mine) || CPU_COUNT(&mine) < 2) GTEST_SKIP() << "needs the last CPU and another";
  Rig rig;
  ServoConfig cfg;
  cfg.realtime = true;  // pins the servo to the last CPU (whether SCHED_FIFO is granted or not)
  ServoLoop loop(rig.rec, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 20);
  pid_t watchdog = -1;
  const auto until = std::chrono::steady_clock::now() + 10s;
  while ((watchdog = spidar::test::thread_named("spidar-watchdog")) < 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(1ms);
  ASSERT_GE(watchdog, 0) << "no thread named spidar-watchdog";
  cpu_set_t where;
  CPU_ZERO(&where);
  ASSERT_EQ(sched_getaffinity(watchdog, sizeof where, &where), 0);
  loop.stop();
  EXPECT_FALSE(CPU_ISSET(servo_cpu, &where)) << "the watchdog may run on the servo's CPU " << servo_cpu;
  EXPECT_GE(CPU_COUNT(&where), 1);
}

TEST(ServoLoop, DisconnectEndsTheLoopCleanlyWithTheFault) {
  SimulatedSpidarParams params;
  params.disconnect_after_s = 1.0;  // time enough for the thread's set-up and first cycles when loaded
  Rig rig(params);
  ServoLoop loop(rig.rec, spidar8(), ServoConfig{}, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  loop.wait();  // ends by itself
  EXPECT_FALSE(loop.running());
  const auto s = loop.stats();
  EXPECT_TRUE(s.faults & kFaultDisconnected);
  EXPECT_NE(s.fault_message.find("disconnected"), std::string::npos);
  EXPECT_GE(rig.rec.safe_requests(), 1);
  EXPECT_GT(s.cycles, 0u);  // it ran before the disconnect (how many cycles is a matter of speed)
}

TEST(ServoLoop, EmergencyStopHoldsMinimumTensionUntilReset) {
  Rig rig;
  struct Pushing final : ForceSource {
    void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
      out.t_ns = in.t_ns;
      for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(0, 0, 3.0));
    }
  };
  ServoLoop loop(rig.rec, spidar8(), ServoConfig{}, std::make_shared<Pushing>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 50);
  loop.emergency_stop();
  const auto at_stop = loop.cycles();
  wait_for_cycles(loop, at_stop + 20);
  FingertipSample s;
  ASSERT_EQ(loop.newest_samples(&s, 1), 1u);
  EXPECT_TRUE(s.faults & kFaultEmergencyStop);
  for (int f = 0; f < 8; ++f) EXPECT_EQ(s.f_W[f][2], 0.0);
  EXPECT_NE(loop.fault_message().find("emergency_stop: emergency stop requested through "
                                      "ServoLoop::emergency_stop()"),
            std::string::npos)
      << loop.fault_message();
  loop.reset_faults();
  wait_for_cycles(loop, loop.cycles() + 20);
  ASSERT_EQ(loop.newest_samples(&s, 1), 1u);
  EXPECT_FALSE(s.faults & kFaultEmergencyStop);
  loop.stop();
}

/// Wraps a device; from cycle `from` on, `count` reads in a row return the previous reading again
/// (repeats 1 … count), as the serial backend does while the device's answer is late.
class LateAnswers final : public Device {
 public:
  LateAnswers(Device& inner, std::uint64_t from, std::uint32_t count)
      : inner_(inner), from_(from), count_(count) {}
  Status open() override { return inner_.open(); }
  void close() override { inner_.close(); }
  const DeviceInfo& info() const override { return inner_.info(); }
  Status read(EncoderReading& out) override {
    const std::uint64_t k = reads_++;
    if (k >= from_ && k < from_ + count_) {
      ++last_.repeats;
      out = last_;
      return Ok{};
    }
    Status s = inner_.read(out);
    last_ = out;
    return s;
  }
  Status write(std::span<const std::int32_t> c) override { return inner_.write(c); }
  void request_safe_state() override { inner_.request_safe_state(); }
  void clear_safe_state() override { inner_.clear_safe_state(); }
  DeviceStatus status() const override { return inner_.status(); }
  Status check_rate(double rate_hz) const override { return inner_.check_rate(rate_hz); }

 private:
  Device& inner_;
  std::uint64_t from_;
  std::uint32_t count_;
  std::uint64_t reads_ = 0;  // servo thread only
  EncoderReading last_;
};

TEST(ServoLoop, LateReadingsAreCountedAndNotPublished) {
  Rig rig;
  LateAnswers late(rig.rec, 100, 7);  // cycles 100 … 106 run on cycle 99's reading
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.max_repeated_readings = 7;
  cfg.force_timeout_s = 1.0;  // this test is about the readings, not the forces' age
  ServoLoop loop(late, spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 140);
  loop.stop();
  const auto s = loop.stats();
  EXPECT_EQ(s.faults & (kFaultStaleCounts | kFaultDisconnected | kFaultReadTimeout), 0u)
      << fault_names(s.faults);
  EXPECT_EQ(s.repeated_readings, 7u);
  EXPECT_EQ(s.longest_repeat, 7u);
  EXPECT_EQ(static_cast<std::uint64_t>(rig.rec.writes()), s.cycles);  // commands every cycle
  // Samples are measurements: none for the repeated cycles, times strictly increasing.
  FingertipSample samples[128];
  const std::size_t n = loop.newest_samples(samples, 128);
  ASSERT_GT(n, 40u);
  bool gap_seen = false;
  for (std::size_t k = 1; k < n; ++k) {
    EXPECT_GT(samples[k - 1].t_ns, samples[k].t_ns);
    EXPECT_GT(samples[k - 1].cycle, samples[k].cycle);
    EXPECT_TRUE(samples[k].cycle < 100 || samples[k].cycle > 106) << samples[k].cycle;
    if (samples[k - 1].cycle == 107 && samples[k].cycle == 99) gap_seen = true;
  }
  EXPECT_TRUE(gap_seen);
}

TEST(ServoLoop, TooManyLateReadingsInARowTripTheSafeState) {
  Rig rig;
  LateAnswers late(rig.rec, 100, 8);  // one more than allowed
  ServoConfig cfg;
  cfg.rate_hz = 1000;
  cfg.max_repeated_readings = 7;
  cfg.force_timeout_s = 1.0;
  struct Pushing final : ForceSource {
    void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
      out.t_ns = in.t_ns;
      for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(0, 0, 2.0));
    }
  };
  ServoLoop loop(late, spidar8(), cfg, std::make_shared<Pushing>());
  ASSERT_TRUE(loop.start().ok());
  wait_for_cycles(loop, 130);
  const int safe_requests = rig.rec.safe_requests();
  loop.stop();
  EXPECT_TRUE(loop.faults() & kFaultStaleCounts) << fault_names(loop.faults());
  EXPECT_GE(safe_requests, 1);
  EXPECT_EQ(loop.stats().longest_repeat, 8u);
  EXPECT_NE(loop.stats().fault_message.find("stale_counts: cycle 107 ran on the same device "
                                            "reading for the 8-th time in a row (bound "
                                            "max_repeated_readings 7)"),
            std::string::npos)
      << loop.stats().fault_message;
  // Latched: the samples after the fault (fresh readings again) display no force.
  FingertipSample s;
  ASSERT_EQ(loop.newest_samples(&s, 1), 1u);
  EXPECT_GT(s.cycle, 107u);
  EXPECT_TRUE(s.faults & kFaultStaleCounts);
  for (int f = 0; f < 8; ++f) EXPECT_EQ(s.f_W[f][2], 0.0);
  loop.reset_faults();
  EXPECT_FALSE(loop.faults() & kFaultStaleCounts);
}

TEST(ServoLoop, BadSetupIsAnError) {
  Rig rig;
  ServoConfig bad;
  bad.rate_hz = 0;
  EXPECT_THROW(ServoLoop(rig.rec, spidar8(), bad, std::make_shared<ZeroForce>()), SpidarError);
  EXPECT_THROW(ServoLoop(rig.rec, spidar8(), ServoConfig{}, nullptr), SpidarError);
  ServoConfig negative;
  negative.max_repeated_readings = -1;
  EXPECT_THROW(ServoLoop(rig.rec, spidar8(), negative, std::make_shared<ZeroForce>()), SpidarError);
  for (double lost : {0.0, 10.5}) {  // the force source's loss cannot be waited for forever
    ServoConfig c;
    c.force_lost_s = lost;
    try {
      ServoLoop l(rig.rec, spidar8(), c, std::make_shared<ZeroForce>());
      ADD_FAILURE() << "force_lost_s " << lost << " accepted";
    } catch (const SpidarError& e) {
      EXPECT_NE(std::string(e.what()).find("force_lost_s"), std::string::npos) << e.what();
    }
  }
  rig.sim.close();
  ServoLoop loop(rig.rec, spidar8(), ServoConfig{}, std::make_shared<ZeroForce>());
  auto st = loop.start();
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("not open"), std::string::npos);
}

}  // namespace
}  // namespace spidar::device
