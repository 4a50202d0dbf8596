// Device faults reach the safe state within the servo cycle their reading arrives: a scripted
// device returns readings with status bits, glitching counts, a frozen clock, fingertips leaving
// the workspace or lengths that do not meet; each test checks the cycle the fault latched in (the
// published sample of that cycle carries it, the one before does not), that the device was asked
// for its safe state in that cycle and got minimum commands, and the fault's text.
//
// No wall-clock assertions: the loop runs without real-time priority and with deadline and
// force-age bounds far out of reach, and the tests count cycles.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <thread>

#include "allocation_counter.hpp"
#include "device_test_support.hpp"
#include "scripted_device.hpp"
#include "spidar/device/fault_log.hpp"
#include "spidar/device/reading_checks.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/device/workspace.hpp"
#include "spidar/strings/position.hpp"

namespace spidar::device {
namespace {

using testing::ScriptedDevice;
using testing::spidar8;
using testing::contains;
using testing::Pushing;


/// Timing faults out of reach: these tests are about the readings.
ServoConfig calm() {
  ServoConfig c;
  c.rate_hz = 1000;
  c.realtime = false;
  c.deadline_periods = 1e6;
  c.stall_limit_s = 1.0;
  c.force_timeout_s = 1e3;
  return c;
}

struct RunResult {
  std::vector<FingertipSample> samples;  // oldest first
  ServoStats stats;
};

RunResult run_cycles(ScriptedDevice& dev, const ServoConfig& cfg, std::uint64_t cycles) {
  EXPECT_TRUE(dev.open().ok());
  ServoLoop loop(dev, spidar8(), cfg, std::make_shared<Pushing>());
  EXPECT_TRUE(loop.start().ok());
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (loop.cycles() < cycles && loop.running() && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  loop.stop();
  RunResult r;
  std::vector<FingertipSample> newest(1024);
  newest.resize(loop.newest_samples(newest.data(), newest.size()));
  r.samples.assign(newest.rbegin(), newest.rend());
  r.stats = loop.stats();
  EXPECT_GE(r.stats.cycles, cycles);
  return r;
}

/// The first published cycle whose sample carries `fault`, or UINT64_MAX.
std::uint64_t first_cycle_with(const RunResult& r, std::uint32_t fault) {
  for (const auto& s : r.samples) {
    if (s.faults & fault) return s.cycle;
  }
  return UINT64_MAX;
}

/// The fault latched in cycle `k` (the cycle of the bad reading, or the last one its bound
/// allows): its sample has the bit and the one before does not; the safe state was requested
/// in that cycle, before its write; that write sent minimum commands, the one before did not.
void expect_latched_in_cycle(const RunResult& r, const ScriptedDevice& dev, std::uint32_t fault,
                             std::uint64_t k) {
  EXPECT_TRUE(r.stats.faults & fault) << fault_names(r.stats.faults);
  EXPECT_EQ(first_cycle_with(r, fault), k) << fault_name(fault);
  EXPECT_EQ(dev.first_safe_request_reads(), k + 1) << "safe state not requested in cycle " << k;
  EXPECT_EQ(dev.write_all_minimum(k - 1), 2) << "cycle " << k - 1 << " already sent minimums";
  EXPECT_EQ(dev.write_all_minimum(k), 1) << "cycle " << k << " did not send minimums";
  EXPECT_FALSE(r.stats.fault_message.empty());
}

TEST(ReadingFaults, DeviceStatusBitsLatchNamedFaultsInTheCycleTheyArrive) {
  ScriptedDevice dev(spidar8(), [](std::uint64_t i, EncoderReading& r) {
    if (i >= 20) r.status_flags |= kFaultOverCurrent;
    if (i >= 30) r.status_flags |= kFaultEmergencyStop;
  });
  const RunResult r = run_cycles(dev, calm(), 40);
  expect_latched_in_cycle(r, dev, kFaultOverCurrent, 20);
  EXPECT_EQ(first_cycle_with(r, kFaultEmergencyStop), 30u);
  const std::string& m = r.stats.fault_message;
  EXPECT_TRUE(contains(m, "over_current: the device reports a motor over its current limit")) << m;
  EXPECT_TRUE(contains(m, "status_flags 0x00000008")) << m;
  EXPECT_TRUE(contains(m, "emergency_stop: the device reports its emergency stop pressed")) << m;
  EXPECT_LT(m.find("over_current"), m.find("emergency_stop")) << "first fault first: " << m;
  EXPECT_EQ(fault_names(r.stats.faults), "over_current,emergency_stop");
}

TEST(ReadingFaults, AStatusBitTheProtocolDoesNotDefineIsAProtocolFault) {
  ScriptedDevice dev(spidar8(), [](std::uint64_t i, EncoderReading& r) {
    if (i >= 12) r.status_flags |= 1u << 20;
  });
  const RunResult r = run_cycles(dev, calm(), 20);
  expect_latched_in_cycle(r, dev, kFaultProtocol, 12);
  EXPECT_TRUE(contains(r.stats.fault_message, "0x00100000 that the protocol does not define"))
      << r.stats.fault_message;
}

TEST(ReadingFaults, DeviceWatchdogLatchesOnlyOnceTheDeviceHasLeftItsStartUpSafeState) {
  // Reading 0 answers open()'s Heartbeat while the device still holds the watchdog safe state it
  // entered between sessions; the first commands clear it. A later trip is a fault.
  ScriptedDevice dev(spidar8(), [](std::uint64_t i, EncoderReading& r) {
    if (i == 0 || i >= 25) r.status_flags |= kFaultWatchdog;
  });
  const RunResult r = run_cycles(dev, calm(), 35);
  expect_latched_in_cycle(r, dev, kFaultWatchdog, 25);
  EXPECT_TRUE(
      contains(r.stats.fault_message, "watchdog: the device reports its heartbeat watchdog"))
      << r.stats.fault_message;
}

TEST(ReadingFaults, EncoderGlitchLatchesInTheCycleOfTheJump) {
  ScriptedDevice dev(spidar8(), [](std::uint64_t i, EncoderReading& r) {
    if (i >= 15) r.counts[7] = 0x2A5A5A;  // random counts on finger 2's second string
  });
  const RunResult r = run_cycles(dev, calm(), 25);
  expect_latched_in_cycle(r, dev, kFaultEncoderGlitch, 15);
  const std::string& m = r.stats.fault_message;
  EXPECT_TRUE(contains(m, "encoder_glitch: finger 2 (" + spidar8().fingers[2].name +
                              ") string 1 (device string 7): length changed by"))
      << m;
  EXPECT_TRUE(contains(m, "max_fingertip_speed_mps 10 m/s")) << m;
}

TEST(ReadingFaults, FastButPossibleMotionIsNoGlitch) {
  // 8 mm per 1 ms reading = 8 m/s, under the 10 m/s bound, back and forth.
  ScriptedDevice* self = nullptr;
  ScriptedDevice dev(spidar8(), [&self](std::uint64_t i, EncoderReading& r) {
    const double x = (i % 2 ? 0.008 : 0.0);
    for (int f = 0; f < 8; ++f) self->set_finger(r.counts, f, self->rest()[f] + Vec3(x, 0, 0));
  });
  self = &dev;
  const RunResult r = run_cycles(dev, calm(), 60);
  EXPECT_EQ(r.stats.faults, 0u) << r.stats.fault_message;
}

TEST(ReadingFaults, FingertipLeavingTheWorkspaceLatchesInTheCycleItIsOutside) {
  // The left thumb moves right 5 mm per reading from reading 10 on (5 m/s: no glitch) and leaves
  // the fulcrums' box grown by the margin (x ≤ 0.366 + 0.1 m).
  ScriptedDevice* self = nullptr;
  auto position = [&self](std::uint64_t i) {
    const double dx = i < 10 ? 0.0 : 0.005 * static_cast<double>(i - 10);
    return Vec3(self->rest()[0] + Vec3(dx, 0, 0));
  };
  ScriptedDevice dev(spidar8(), [&](std::uint64_t i, EncoderReading& r) {
    self->set_finger(r.counts, 0, position(i));
  });
  self = &dev;
  const ServoConfig cfg = calm();
  const Workspace box = device_workspace(spidar8(), cfg.workspace_margin_m);
  EXPECT_NEAR(box.hi_W.x(), 0.466, 1e-9);
  std::uint64_t k = 0;
  while (position(k).x() <= box.hi_W.x()) ++k;
  // Clear of the face by more than the counts' quantisation either side.
  ASSERT_GT(position(k).x() - box.hi_W.x(), 2e-4);
  ASSERT_GT(box.hi_W.x() - position(k - 1).x(), 2e-4);
  const RunResult r = run_cycles(dev, cfg, k + 10);
  expect_latched_in_cycle(r, dev, kFaultWorkspace, k);
  EXPECT_FALSE(r.stats.faults & kFaultEncoderGlitch) << r.stats.fault_message;
  EXPECT_TRUE(contains(r.stats.fault_message, "workspace: finger 0 (left_thumb) solved at ("))
      << r.stats.fault_message;
  EXPECT_TRUE(contains(r.stats.fault_message, "x outside [-0.466, 0.466] m by"))
      << r.stats.fault_message;
}

TEST(ReadingFaults, InvalidLengthsLatchInconsistentOnceTheirBoundIsExceeded) {
  const auto& cfg8 = spidar8();
  const auto& ch = cfg8.fingers[1].channels[0];
  const auto negative = static_cast<std::int32_t>(
      strings::wrap_counter(strings::length_to_counts(ch, -0.05), cfg8.counter_bits));
  ScriptedDevice dev(cfg8, [negative](std::uint64_t i, EncoderReading& r) {
    if (i >= 12) r.counts[3] = negative;  // finger 1's first string reads −5 cm
  });
  ServoConfig cfg = calm();
  cfg.max_inconsistent_cycles = 3;    // readings 12, 13, 14 are tolerated, 15 is not
  cfg.max_fingertip_speed_mps = 1e6;  // the jump itself is not what is tested here
  const RunResult r = run_cycles(dev, cfg, 25);
  expect_latched_in_cycle(r, dev, kFaultInconsistent, 15);
  EXPECT_TRUE(contains(r.stats.fault_message,
                       "inconsistent: finger 1 (left_index): no position for 4 new readings in a "
                       "row (bound max_inconsistent_cycles 3): string 0 (device string 3) length"))
      << r.stats.fault_message;
}

TEST(ReadingFaults, LengthsThatDoNotMeetLatchInconsistentWithTheirResidual) {
  const auto& cfg8 = spidar8();
  ScriptedDevice* self = nullptr;
  // Finger 4's first string 0.6 m too long: its three spheres no longer meet.
  auto lengths = [&cfg8](const Vec3& p) {
    strings::StringVec l = strings::string_lengths(cfg8.fingers[4].geometry, p);
    l[0] += 0.6;
    return l;
  };
  ScriptedDevice dev(cfg8, [&](std::uint64_t i, EncoderReading& r) {
    if (i < 12) return;
    const strings::StringVec l = lengths(self->rest()[4]);
    const int k0 = self->first_string(4);
    r.counts[static_cast<std::size_t>(k0)] = static_cast<std::int32_t>(strings::wrap_counter(
        strings::length_to_counts(cfg8.fingers[4].channels[0], l[0]), cfg8.counter_bits));
  });
  self = &dev;
  const strings::StringVec bad = lengths(dev.rest()[4]);
  const auto est = strings::solve_position(cfg8.fingers[4].geometry,
                                           std::span<const double>(bad.data(), bad.size()));
  ASSERT_TRUE(est.ok());
  ASSERT_FALSE(est->consistent) << "precondition: these lengths must not meet";
  ServoConfig cfg = calm();
  cfg.max_inconsistent_cycles = 2;
  cfg.max_fingertip_speed_mps = 1e6;
  cfg.workspace_margin_m = 100.0;  // wherever the least-squares point lands
  const RunResult r = run_cycles(dev, cfg, 25);
  expect_latched_in_cycle(r, dev, kFaultInconsistent, 14);
  EXPECT_TRUE(contains(r.stats.fault_message, "inconsistent: finger 4 (" + cfg8.fingers[4].name +
                                                  "): string lengths did not meet in one point"))
      << r.stats.fault_message;
  EXPECT_TRUE(contains(r.stats.fault_message, "RMS length residual")) << r.stats.fault_message;
}

TEST(ReadingFaults, FrozenDeviceClockLatchesOnceItsBoundIsReached) {
  ScriptedDevice dev(spidar8(), [](std::uint64_t i, EncoderReading& r) {
    if (i >= 10) r.device_time_us = 9000;  // reading 9's time, from reading 10 on
  });
  ServoConfig cfg = calm();
  cfg.max_frozen_clock_readings = 4;  // readings 10, 11, 12, 13 did not advance: 13 latches
  const RunResult r = run_cycles(dev, cfg, 25);
  expect_latched_in_cycle(r, dev, kFaultFrozenClock, 13);
  EXPECT_TRUE(contains(r.stats.fault_message,
                       "frozen_clock: the device clock stayed at 9000 us: it did not advance on 4 "
                       "new readings in a row (bound max_frozen_clock_readings 4)"))
      << r.stats.fault_message;
}

TEST(ReadingFaults, HealthyScriptedDeviceHasNoFault) {
  ScriptedDevice dev(spidar8(), nullptr);
  const RunResult r = run_cycles(dev, calm(), 50);
  EXPECT_EQ(r.stats.faults, 0u) << r.stats.fault_message;
  EXPECT_TRUE(r.stats.fault_message.empty());
  EXPECT_EQ(dev.first_safe_request_reads(), dev.reads());  // only when the loop stopped
  EXPECT_EQ(dev.write_all_minimum(10), 2);                 // the forces were displayed
}

TEST(ReadingFaults, SimulatedFingertipsYankedByStrongForcesTripNoReadingCheck) {
  // No false alarms on a healthy device: the simulated SPIDAR-8 with forces stepping between 0 and
  // 15 N on every finger every 50 cycles (the fingertips jump through their impedance).
  SimulatedSpidar sim(spidar8(), {}, testing::hovering(spidar8()));
  ASSERT_TRUE(sim.open().ok());
  struct Stepping final : ForceSource {
    void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
      out.t_ns = in.t_ns;
      const double F = (in.cycle / 50) % 2 ? 15.0 : 0.0;
      for (int f = 0; f < kMaxFingers; ++f) out.set_force(f, Vec3(F, f % 2 ? F : -F, -F));
    }
  };
  ServoLoop loop(sim, spidar8(), calm(), std::make_shared<Stepping>());
  ASSERT_TRUE(loop.start().ok());
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (loop.cycles() < 600 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  loop.stop();
  const ServoStats s = loop.stats();
  EXPECT_GE(s.cycles, 600u);
  EXPECT_EQ(s.faults, 0u) << s.fault_message;
}

TEST(ReadingFaults, TheCycleThatLatchesAFaultDoesNotAllocate) {
  namespace alloc = spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  // A glitch, a status bit and a finger leaving the workspace, all latched (with their texts) in
  // the same cycle, while allocations are counted.
  ScriptedDevice* self = nullptr;
  ScriptedDevice dev(spidar8(), [&self](std::uint64_t i, EncoderReading& r) {
    if (i < 200) return;
    r.status_flags |= kFaultOverCurrent;
    r.counts[7] = 0x2A5A5A;
    self->set_finger(r.counts, 5, self->rest()[5] + Vec3(0, 0, 2.0));
  });
  self = &dev;
  ASSERT_TRUE(dev.open().ok());
  ServoConfig cfg = calm();
  cfg.on_thread_start = [] { alloc::mark_this_thread(); };
  ServoLoop loop(dev, spidar8(), cfg, std::make_shared<Pushing>());
  ASSERT_TRUE(loop.start().ok());
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (loop.cycles() < 50 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  alloc::start();
  while (loop.cycles() < 250 && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  alloc::stop();
  loop.stop();
  EXPECT_EQ(alloc::count(), 0);
  const ServoStats s = loop.stats();
  EXPECT_EQ(s.faults & (kFaultOverCurrent | kFaultEncoderGlitch | kFaultWorkspace),
            kFaultOverCurrent | kFaultEncoderGlitch | kFaultWorkspace)
      << fault_names(s.faults);
  // The farthest finger is named: the glitched one, far beyond finger 5.
  EXPECT_TRUE(contains(s.fault_message, "workspace: finger 2 (left_middle) solved at ("))
      << s.fault_message;
}

TEST(ReadingFaults, ThresholdsAreValidated) {
  ScriptedDevice dev(spidar8(), nullptr);
  auto expect_rejected = [&dev](ServoConfig c, const std::string& field) {
    try {
      ServoLoop loop(dev, spidar8(), c, std::make_shared<ZeroForce>());
      ADD_FAILURE() << field << " accepted";
    } catch (const SpidarError& e) {
      EXPECT_TRUE(contains(e.what(), field)) << e.what();
    }
  };
  ServoConfig c;
  c.workspace_margin_m = -0.01;
  expect_rejected(c, "workspace_margin_m");
  c = {};
  c.workspace_margin_m = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(c, "workspace_margin_m");
  c = {};
  c.max_inconsistent_cycles = -1;
  expect_rejected(c, "max_inconsistent_cycles");
  c = {};
  c.max_fingertip_speed_mps = 0.0;
  expect_rejected(c, "max_fingertip_speed_mps");
  c = {};
  c.max_fingertip_speed_mps = std::numeric_limits<double>::infinity();
  expect_rejected(c, "max_fingertip_speed_mps");
  c = {};
  c.max_frozen_clock_readings = 1;
  expect_rejected(c, "max_frozen_clock_readings");
}

TEST(Workspace, IsTheFulcrumsBoxGrownByTheMargin) {
  const Workspace w = device_workspace(spidar8(), 0.1);
  EXPECT_NEAR(w.lo_W.x(), -0.466, 1e-12);
  EXPECT_NEAR(w.hi_W.y(), 0.383, 1e-12);
  EXPECT_NEAR(w.lo_W.z(), -0.330, 1e-12);
  EXPECT_EQ(workspace_excess(w, {0.0, 0.0, 0.0}).axis, -1);
  EXPECT_EQ(workspace_excess(w, {0.46, -0.38, 0.32}).distance_m, 0.0);
  const WorkspaceExcess e = workspace_excess(w, {0.5, 300.0, -0.4});
  EXPECT_EQ(e.axis, 1);
  EXPECT_NEAR(e.distance_m, 300.0 - 0.383, 1e-9);
  EXPECT_NEAR(e.limit_m, 0.383, 1e-12);
  const WorkspaceExcess nan = workspace_excess(w, {0.0, std::nan(""), 0.0});
  EXPECT_EQ(nan.axis, 1);
  EXPECT_TRUE(std::isinf(nan.distance_m));
}

TEST(FaultLog, DescribesLatchedFaultsFirstFirstAndCutsLongTexts) {
  FaultLog log;
  EXPECT_EQ(log.describe(0), "");
  log.recordf(kFaultWorkspace, "finger %d out", 3);
  log.record(kFaultOverCurrent | kFaultEmergencyStop, "device says so");
  EXPECT_EQ(log.describe(kFaultWorkspace | kFaultOverCurrent),
            "workspace: finger 3 out; over_current: device says so");
  EXPECT_EQ(log.describe(kFaultStaleCounts), "stale_counts: no details recorded");
  const std::string longer(2 * FaultLog::kTextSize, 'x');
  log.record(kFaultFrozenClock, longer.c_str());
  EXPECT_EQ(log.describe(kFaultFrozenClock).size(),
            std::string("frozen_clock: ").size() + FaultLog::kTextSize - 1);
}

}  // namespace
}  // namespace spidar::device
