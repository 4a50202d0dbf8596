// One servo cycle without the loop: the published sample carries the tensions and commands the
// cycle computed (checked against an independent tension solve), and the counts it turns into
// positions are unwrapped across the counters' wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "device_test_support.hpp"
#include "reference_tension.hpp"
#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/unwrapped_counts.hpp"
#include "spidar/strings/encoder.hpp"
#include "spidar/strings/motor.hpp"

namespace spidar::device {
namespace {

using testing::spidar8;

DeviceInfo spidar8_info() {
  DeviceInfo info;
  info.name = "ideal SPIDAR-8";
  info.string_count = spidar8().string_count();
  info.counter_bits = spidar8().counter_bits;
  info.command_min = spidar8().command_range().min;
  info.command_max = 4095;
  return info;
}

using Shift = std::array<std::int64_t, kMaxDeviceStrings>;

/// The counts ideal encoders give with fingertip f at p_W[f] (config channels, unwrapped).
Shift ideal_counts(const std::vector<Vec3>& p_W) {
  const auto& cfg = spidar8();
  Shift c{};
  for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
    const auto& fc = cfg.fingers[f];
    for (int i = 0; i < fc.geometry.n; ++i)
      c[static_cast<std::size_t>(cfg.first_string(static_cast<int>(f)) + i)] =
          strings::length_to_counts(fc.channels[i], (fc.geometry.p_WA[i] - p_W[f]).norm());
  }
  return c;
}

/// The reading of those ideal encoders with string k's counter `shift[k]` counts on from the
/// config's zero, wrapped to the device's width.
EncoderReading ideal_reading(const std::vector<Vec3>& p_W, const Shift& shift = {}) {
  const auto& cfg = spidar8();
  EncoderReading r;
  r.string_count = cfg.string_count();
  const Shift c = ideal_counts(p_W);
  for (int k = 0; k < r.string_count; ++k)
    r.counts[k] =
        static_cast<std::int32_t>(strings::wrap_counter(c[k] + shift[k], cfg.counter_bits));
  return r;
}

std::vector<Vec3> rest(double dz = 0) {
  auto p = rest_points(spidar8());
  for (auto& x : p) x.z() += dz;
  return p;
}

TEST(ServoCycle, SampleCarriesTheTensionsAndCommandsOfAnIndependentSolve) {
  const auto& cfg = spidar8();
  ServoCycle cycle(cfg, spidar8_info());
  FingertipSample s;
  cycle.measure(ideal_reading(rest()), s);
  ASSERT_EQ(s.finger_count, 8);
  ASSERT_EQ(s.string_count, 24);
  ForceFrame force;
  // Forces of several sizes and directions, one beyond the strings' reach (clipped to the cone).
  const Vec3 dirs[] = {{0.5, -0.5, 1.0}, {-2, 0, 0}, {0, 3, -1},  {0, 0, -50},
                       {1, 1, 1},        {0, 0, 0},  {-1, -1, 4}, {2, -3, 0.5}};
  for (int f = 0; f < 8; ++f) force.set_force(f, dirs[f]);
  std::vector<std::int32_t> commands(24, -1);
  cycle.command(force, false, s, commands);
  const auto limits = cfg.effective_limits();
  for (int f = 0; f < 8; ++f) {
    const auto& g = cfg.fingers[f].geometry;
    const Vec3 p = fingertip_position(s, f);
    Eigen::MatrixXd U(3, g.n);
    for (int i = 0; i < g.n; ++i) U.col(i) = (g.p_WA[i] - p).normalized();
    const auto ref = reference::brute_force_tensions(U, force.force(f), limits.t_min, limits.t_max);
    Vec3 shown = Vec3::Zero();
    for (int i = 0; i < g.n; ++i) {
      const int k = cfg.first_string(f) + i;
      EXPECT_NEAR(s.tension[k], ref.t[i], 1e-6) << "finger " << f << " string " << i;
      EXPECT_EQ(s.command[k], commands[k]) << k;
      EXPECT_EQ(commands[k], std::clamp(strings::tension_to_command(cfg.motor, ref.t[i]).dac,
                                        spidar8_info().command_min, spidar8_info().command_max))
          << k;
      shown += s.tension[k] * U.col(i);
    }
    EXPECT_NEAR((fingertip_force(s, f) - shown).norm(), 0.0, 1e-9) << f;
  }
  // The safe state: minimum commands, no tensions, no force.
  cycle.command(force, true, s, commands);
  for (int k = 0; k < 24; ++k) {
    EXPECT_EQ(s.tension[k], 0.0);
    EXPECT_EQ(s.command[k], spidar8_info().command_min);
    EXPECT_EQ(commands[k], spidar8_info().command_min);
  }
  for (int f = 0; f < 8; ++f) EXPECT_EQ(fingertip_force(s, f), Vec3::Zero());
}

TEST(ServoCycle, CountsAreUnwrappedAcrossTheCountersWrap) {
  const auto& cfg = spidar8();
  // Counters that start just below the top of their 24-bit range: a fingertip moving 1 cm up
  // (up to a few hundred counts) wraps those whose count grows to the bottom.
  Shift shift{};
  const Shift at_rest = ideal_counts(rest());
  for (int k = 0; k < 24; ++k) shift[k] = (std::int64_t{1} << 23) - 50 - at_rest[k];
  ServoCycle cycle(cfg, spidar8_info());
  FingertipSample first;
  cycle.measure(ideal_reading(rest(), shift), first);
  // The first reading is taken as is: the config's lengths are shifted by `shift` counts, so
  // compare the motion, not the absolute lengths.
  const auto lengths0 = std::vector<double>(cycle.lengths().begin(), cycle.lengths().end());
  FingertipSample moved;
  const EncoderReading r1 = ideal_reading(rest(0.01), shift);
  cycle.measure(r1, moved);
  bool wrapped = false;
  for (int k = 0; k < 24; ++k) {
    const auto raw0 = ideal_reading(rest(), shift).counts[k];
    wrapped = wrapped || std::abs(static_cast<std::int64_t>(r1.counts[k]) - raw0) > (1 << 22);
  }
  ASSERT_TRUE(wrapped) << "the test should make a counter wrap";
  // Every string's length changed by what 1 cm of motion changes it, never by 2^24 counts.
  const auto truth0 = rest(), truth1 = rest(0.01);
  for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
    const auto& fc = cfg.fingers[f];
    for (int i = 0; i < fc.geometry.n; ++i) {
      const int k = cfg.first_string(static_cast<int>(f)) + i;
      const double dl_true =
          (fc.geometry.p_WA[i] - truth1[f]).norm() - (fc.geometry.p_WA[i] - truth0[f]).norm();
      EXPECT_NEAR(
          cycle.lengths()[static_cast<std::size_t>(k)] - lengths0[static_cast<std::size_t>(k)],
          dl_true, 2 * fc.channels[i].metres_per_count)
          << k;
    }
  }
  // The same counts, unwrapped by the class calibration uses, are the cycle's.
  UnwrappedCounts u(24, cfg.counter_bits);
  u.update(ideal_reading(rest(), shift));
  u.update(r1);
  for (int k = 0; k < 24; ++k)
    EXPECT_EQ(u.counts()[static_cast<std::size_t>(k)], cycle.counts()[static_cast<std::size_t>(k)])
        << k;
}

}  // namespace
}  // namespace spidar::device
