// Fingertip samples at a camera frame's exposure time, and the simulated device's ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <span>
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

// read_back_to reads as few samples as reach back to the time asked for, and the interpolation
// on them equals the one on the whole history, for every time the history covers.
TEST(SampleInterpolation, ReadBackToReadsOnlyWhatReachesTheTimeAndInterpolatesAsTheWholeRing) {
  const auto ring = linear_samples(1000);  // 1 s of samples, 1 ms apart, newest first
  std::vector<std::size_t> asked;
  auto read = [&](FingertipSample* out, std::size_t max) {
    asked.push_back(max);
    const std::size_t n = std::min(max, ring.size());
    std::copy(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(n), out);
    return n;
  };
  std::vector<FingertipSample> buf(1000);
  const std::int64_t newest = ring.front().t_ns;
  // 3.5 ms ago: the first 32 are enough.
  std::size_t n = read_back_to(read, newest - 3'500'000, std::span(buf), 32);
  EXPECT_EQ(n, 32u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32}));
  // 100.5 ms ago: 32, 128.
  asked.clear();
  n = read_back_to(read, newest - 100'500'000, std::span(buf), 32);
  EXPECT_EQ(n, 128u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32, 128}));
  // Older than the ring: all of the buffer, then no more tries.
  asked.clear();
  n = read_back_to(read, newest - 5'000'000'000, std::span(buf), 32);
  EXPECT_EQ(n, 1000u);
  EXPECT_EQ(asked, (std::vector<std::size_t>{32, 128, 512, 1000}));
  // A source with fewer samples than asked for: what it has, in one try.
  asked.clear();
  auto short_read = [&](FingertipSample* out, std::size_t max) {
    asked.push_back(max);
    const std::size_t n5 = std::min<std::size_t>(max, 5);
    std::copy(ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(n5), out);
    return n5;
  };
  EXPECT_EQ(read_back_to(short_read, newest - 100'000'000, std::span(buf), 32), 5u);
  EXPECT_EQ(asked.size(), 1u);
  // An empty source.
  auto none = [](FingertipSample*, std::size_t) { return std::size_t{0}; };
  EXPECT_EQ(read_back_to(none, newest, std::span(buf), 32), 0u);
  // The interpolation on what was read equals the one on the whole ring.
  for (std::int64_t ago : {0LL, 700'000LL, 31'200'000LL, 32'000'000LL, 250'300'000LL, 998'900'000LL}) {
    const std::int64_t t = newest - ago;
    n = read_back_to(read, t, std::span(buf), 32);
    const auto part = interpolate_samples(std::span<const FingertipSample>(buf.data(), n), t);
    const auto whole = interpolate_samples(ring, t);
    ASSERT_EQ(part.has_value(), whole.has_value()) << ago;
    ASSERT_TRUE(whole.has_value()) << ago;
    EXPECT_EQ(part->t_ns, whole->t_ns) << ago;
    EXPECT_EQ(part->p_W, whole->p_W) << ago;
    EXPECT_EQ(part->tension, whole->tension) << ago;
    EXPECT_EQ(part->cycle, whole->cycle) << ago;
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
