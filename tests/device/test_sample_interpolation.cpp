// Fingertip samples at a camera frame's exposure time, and the simulated device's ground truth.
#include <gtest/gtest.h>

#include <vector>

#include "device_test_support.hpp"
#include "spidar/device/sample_interpolation.hpp"

namespace spidar::device {
namespace {

// Samples of a motion that is linear in time, every 1 ms, newest first.
std::vector<FingertipSample> linear_samples(int n) {
  std::vector<FingertipSample> s;
  for (int k = n - 1; k >= 0; --k) {
    FingertipSample x;
    x.t_ns = 1'000'000'000 + k * 1'000'000;
    x.cycle = static_cast<std::uint64_t>(k);
    x.finger_count = 2;
    x.consistent = 3u;
    for (int f = 0; f < 2; ++f) {
      x.p_W[f] = {0.001 * k + f, -0.002 * k, 0.5};
      x.f_W[f] = {0.1 * k, 0.0, -1.0 * f};
    }
    x.string_count = 2;
    x.tension = {0.35 + 0.2 * k, 3.0};
    x.command = {100 + k, 7};
    s.push_back(x);
  }
  return s;
}

TEST(SampleInterpolation, LinearBetweenNeighbours) {
  const auto s = linear_samples(20);
  for (double k : {0.0, 0.25, 3.5, 11.9, 18.999}) {
    const std::int64_t t = 1'000'000'000 + static_cast<std::int64_t>(k * 1e6);
    const auto x = interpolate_samples(s, t);
    ASSERT_TRUE(x.has_value()) << k;
    EXPECT_EQ(x->t_ns, t);
    EXPECT_NEAR(x->p_W[1][0], 0.001 * k + 1, 1e-9);
    EXPECT_NEAR(x->p_W[0][1], -0.002 * k, 1e-9);
    EXPECT_NEAR(x->f_W[0][0], 0.1 * k, 1e-9);
    EXPECT_NEAR(x->tension[0], 0.35 + 0.2 * k, 1e-9);
    EXPECT_NEAR(x->tension[1], 3.0, 1e-12);
    EXPECT_EQ(x->command[0], 100 + static_cast<int>(k));  // the command in effect at t
    EXPECT_EQ(x->cycle, static_cast<std::uint64_t>(k));
  }
}

TEST(SampleInterpolation, HoldsTheNewestBrieflyAndRefusesOutside) {
  const auto s = linear_samples(10);
  const std::int64_t newest = s.front().t_ns;
  const auto held = interpolate_samples(s, newest + 2'000'000, 5'000'000);
  ASSERT_TRUE(held.has_value());
  EXPECT_DOUBLE_EQ(held->p_W[0][0], s.front().p_W[0][0]);
  EXPECT_FALSE(interpolate_samples(s, newest + 6'000'000, 5'000'000).has_value());
  EXPECT_FALSE(interpolate_samples(s, s.back().t_ns - 1).has_value());
  EXPECT_FALSE(interpolate_samples({}, newest).has_value());
  // Exactly on a sample: that sample.
  const auto on = interpolate_samples(s, s[3].t_ns);
  ASSERT_TRUE(on.has_value());
  EXPECT_DOUBLE_EQ(on->p_W[0][0], s[3].p_W[0][0]);
}

TEST(SampleInterpolation, FaultsAreOredAndConsistencyAnded) {
  auto s = linear_samples(3);
  s[0].faults = 4u;
  s[1].consistent = 1u;
  const auto x = interpolate_samples(s, (s[0].t_ns + s[1].t_ns) / 2);
  ASSERT_TRUE(x.has_value());
  EXPECT_EQ(x->faults, 4u);
  EXPECT_EQ(x->consistent, 1u);
}

TEST(SimulatedSpidar, PublishesItsGroundTruthAtEveryRead) {
  const auto& cfg = testing::spidar8();
  SimulatedSpidarParams p;
  p.fixed_step_s = 1e-3;
  SimulatedSpidar sim(cfg, p, testing::hovering(cfg));
  ASSERT_TRUE(sim.open().ok());
  EncoderReading r;
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(sim.read(r).ok());
  std::vector<FingertipSample> truth(64);
  const std::size_t n = sim.truth_samples(truth.data(), truth.size());
  ASSERT_EQ(n, 30u);
  EXPECT_EQ(truth[0].cycle, 29u);
  EXPECT_EQ(truth[0].t_ns, r.host_time_ns);
  EXPECT_GT(truth[0].t_ns, truth[29].t_ns);
  const SimulatedTruth t = sim.truth();
  ASSERT_EQ(truth[0].finger_count, 8);
  for (int f = 0; f < 8; ++f) {
    for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(truth[0].p_W[f][k], t.p_W_fingertip[f][k]);
  }
}

}  // namespace
}  // namespace spidar::device
