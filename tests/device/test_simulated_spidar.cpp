#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "device_test_support.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/strings/motor.hpp"
#include "spidar/strings/position.hpp"

namespace spidar::device {
namespace {

using testing::spidar8;

SimulatedSpidarParams deterministic() {
  SimulatedSpidarParams p;
  p.fixed_step_s = 1e-3;
  return p;
}

/// Host-side positions from a reading, with the config's channels.
std::vector<Vec3> positions(const strings::DeviceConfig& cfg, const EncoderReading& r) {
  std::vector<Vec3> out;
  int k = 0;
  for (const auto& f : cfg.fingers) {
    std::vector<double> l;
    for (int i = 0; i < f.geometry.n; ++i, ++k)
      l.push_back(strings::counts_to_length(f.channels[i], r.counts[k]));
    out.push_back(strings::solve_position(f.geometry, l).value().p_WF);
  }
  return out;
}

TEST(SimulatedSpidar, EncodersLocateTheFingertipsAtMinimumTension) {
  const auto& cfg = spidar8();
  SimulatedSpidar sim(cfg, deterministic(), testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  EXPECT_EQ(sim.info().string_count, 24);
  EXPECT_EQ(sim.info().command_max, 4095);  // the drive saturates below t_max
  std::vector<std::int32_t> cmd(24, sim.info().command_min);
  EncoderReading r;
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(sim.read(r).ok());
    ASSERT_TRUE(sim.write(cmd).ok());
  }
  const auto truth = sim.truth();
  const auto est = positions(cfg, r);
  for (int f = 0; f < 8; ++f) {
    EXPECT_LT((est[f] - truth.p_W_fingertip[f]).norm(), 2e-4) << f;  // noise + quantisation
  }
  EXPECT_NEAR(truth.t_s, 0.5, 1e-9);
  EXPECT_EQ(r.device_time_us, 500000u);
}

// The user's hands keep moving while the servo thread is stalled: after a late read the
// simulated device's time (and so the ground truth the camera films) is the time since open,
// not behind it (it used to advance at most 0.5 s per read, so every stall longer than that
// left the truth lagging the wall clock for the rest of the run).
TEST(SimulatedSpidar, DeviceTimeIsTheTimeSinceOpenAfterAStalledRead) {
  const auto& cfg = spidar8();
  SimulatedSpidar sim(cfg, SimulatedSpidarParams{}, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  const std::int64_t t_open = core::monotonic_ns();
  EncoderReading r;
  ASSERT_TRUE(sim.read(r).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  ASSERT_TRUE(sim.read(r).ok());
  const double since_open_s = core::ns_to_s(core::monotonic_ns() - t_open);
  // Bounds only (no timing assertion): the read came ≥ 0.8 s after open, and the device's
  // time cannot be ahead of the wall clock.
  EXPECT_GE(r.device_time_us, 800000u);
  EXPECT_LE(r.device_time_us * 1e-6, since_open_s + 1e-3);
  EXPECT_NEAR(sim.truth().t_s, r.device_time_us * 1e-6, 1e-6);
}

TEST(SimulatedSpidar, MotorsLagAndSaturateAndSlackStringsSag) {
  const auto& cfg = spidar8();
  auto params = deterministic();
  params.count_noise = 0;
  params.motor_time_constant = 2e-3;
  SimulatedSpidar sim(cfg, params, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  sim.clear_safe_state();
  std::vector<std::int32_t> cmd(24, sim.info().command_min);
  cmd[0] = strings::tension_to_command(cfg.motor, 10.0).dac;
  cmd[1] = 1'000'000;  // beyond the DAC: clamped
  ASSERT_TRUE(sim.write(cmd).ok());
  EXPECT_EQ(sim.applied_commands()[1], sim.info().command_max);
  const double t0 = sim.truth().tension[0];
  sim.advance(2e-3);  // one time constant
  const double t1 = sim.truth().tension[0];
  EXPECT_NEAR((t1 - t0) / (10.0 - t0), 1.0 - std::exp(-1.0), 0.01);
  sim.advance(0.05);
  EXPECT_NEAR(sim.truth().tension[1], strings::max_drive_tension(cfg.motor), 1e-6);

  // Slack: command zero tension on finger 2's strings (below the drive minimum is impossible, so
  // lower the minimum via a zero command and compare readings).
  EncoderReading taut, slack;
  ASSERT_TRUE(sim.read(taut).ok());
  std::vector<std::int32_t> zero(24, 0);
  ASSERT_TRUE(sim.write(zero).ok());
  // command_min is the t_min command, so zero is clamped up: the strings stay taut.
  EXPECT_EQ(sim.applied_commands()[6], sim.info().command_min);
  EXPECT_FALSE(sim.truth().slack[6]);
}

TEST(SimulatedSpidar, SlackStringReadsLongAndPullsNothing) {
  auto cfg = spidar8();
  cfg.tension.t_min = 0.0;  // allow commanding zero tension
  auto params = deterministic();
  params.count_noise = 0;
  SimulatedSpidar sim(cfg, params, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  sim.clear_safe_state();
  EXPECT_EQ(sim.info().command_min, 0);
  std::vector<std::int32_t> cmd(24, strings::tension_to_command(cfg.motor, 0.35).dac);
  ASSERT_TRUE(sim.write(cmd).ok());
  sim.advance(0.05);
  EncoderReading taut;
  ASSERT_TRUE(sim.read(taut).ok());
  const auto p = sim.truth().p_W_fingertip[0];
  cmd[0] = 0;
  ASSERT_TRUE(sim.write(cmd).ok());
  sim.advance(0.05);
  EncoderReading slack;
  ASSERT_TRUE(sim.read(slack).ok());
  const auto truth = sim.truth();
  EXPECT_TRUE(truth.slack[0]);
  const double true_len = (cfg.fingers[0].geometry.p_WA[0] - truth.p_W_fingertip[0]).norm();
  const double read_len = strings::counts_to_length(cfg.fingers[0].channels[0], slack.counts[0]);
  EXPECT_NEAR(read_len - true_len, params.slack_sag, 3e-4);
  (void)p;
}

TEST(SimulatedSpidar, DisplayedForcePushesTheFingertipThroughItsImpedance) {
  const auto& cfg = spidar8();
  auto params = deterministic();
  params.count_noise = 0;
  const Vec3 goal(-0.03, 0.02, -0.01);
  auto still = std::make_shared<ScriptedFingertips>([goal](double, std::span<Vec3> g) {
    for (auto& p : g) p = goal;
  });
  SimulatedSpidar sim(cfg, params, still);
  ASSERT_TRUE(sim.open().ok());
  sim.clear_safe_state();
  const auto& f1 = cfg.fingers[1].geometry;
  // Pull finger 1 with 5 N on every string for a second: it settles at goal + F/k.
  std::vector<std::int32_t> cmd(24, sim.info().command_min);
  for (int i = 0; i < 3; ++i) cmd[3 + i] = strings::tension_to_command(cfg.motor, 5.0).dac;
  ASSERT_TRUE(sim.write(cmd).ok());
  sim.advance(1.0);
  const auto truth = sim.truth();
  const Vec3 F = truth.f_W_strings[1];
  const Vec3 expected = goal + F / params.impedance.stiffness;
  EXPECT_LT((truth.p_W_fingertip[1] - expected).norm(), 1e-6);
  EXPECT_GT(F.norm(), 5.0);
  // The force is the sum of tensions along the strings from the fingertip.
  Vec3 sum = Vec3::Zero();
  for (int i = 0; i < 3; ++i) sum += truth.tension[3 + i] * (f1.p_WA[i] - truth.p_W_fingertip[1]).normalized();
  EXPECT_LT((sum - F).norm(), 1e-9);
}

TEST(SimulatedSpidar, SafeStateActsAtOnceAndInjectedDisconnectFails) {
  const auto& cfg = spidar8();
  auto params = deterministic();
  params.disconnect_after_s = 0.05;
  SimulatedSpidar sim(cfg, params, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  sim.clear_safe_state();
  std::vector<std::int32_t> cmd(24, 3000);
  ASSERT_TRUE(sim.write(cmd).ok());
  sim.request_safe_state();
  sim.advance(0.02);
  for (double t : sim.truth().tension) EXPECT_NEAR(t, cfg.effective_limits().t_min, 0.01);
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  EncoderReading r;
  auto st = sim.read(r);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("disconnected"), std::string::npos);
  EXPECT_TRUE(sim.status().faults & kFaultDisconnected);
  EXPECT_FALSE(sim.write(cmd).ok());
  EXPECT_EQ(fault_names(sim.status().faults), "disconnected");
}

TEST(SimulatedSpidar, CountersWrapAtTheirWidth) {
  auto cfg = spidar8();
  cfg.counter_bits = 10;  // ±512 counts = ±1.5 cm: the hovering motion wraps often
  auto params = deterministic();
  params.count_noise = 0;
  SimulatedSpidar sim(cfg, params, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  EncoderReading r;
  bool wrapped = false;
  for (int k = 0; k < 3000; ++k) {
    ASSERT_TRUE(sim.read(r).ok());
    for (int i = 0; i < 24; ++i) {
      ASSERT_GE(r.counts[i], -512);
      ASSERT_LT(r.counts[i], 512);
      wrapped = wrapped || std::abs(r.counts[i]) > 400;
    }
  }
  EXPECT_TRUE(wrapped);
}

}  // namespace
}  // namespace spidar::device
