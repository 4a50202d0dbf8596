#include <gtest/gtest.h>

#include <random>

#include "spidar/strings/encoder.hpp"
#include "spidar/strings/motor.hpp"

namespace spidar::strings {
namespace {

TEST(Encoder, CountsAndLengthsRoundTrip) {
  for (int sign : {1, -1}) {
    const EncoderChannel ch{sign, 2.924e-5, 0.41};
    for (std::int64_t c : {-5000000LL, -1LL, 0LL, 1LL, 123456LL, 9000000LL}) {
      EXPECT_EQ(length_to_counts(ch, counts_to_length(ch, c)), c);
    }
    EXPECT_DOUBLE_EQ(counts_to_length(ch, 1000), 0.41 + sign * 0.02924);
    // Rounding to the nearest count: within half a count.
    EXPECT_NEAR(counts_to_length(ch, length_to_counts(ch, 0.5)), 0.5, 0.5 * 2.924e-5 + 1e-15);
  }
}

TEST(Encoder, WrapCounterIsSigned24Bit) {
  EXPECT_EQ(wrap_counter(0, 24), 0);
  EXPECT_EQ(wrap_counter((1 << 23) - 1, 24), (1 << 23) - 1);
  EXPECT_EQ(wrap_counter(1 << 23, 24), -(1 << 23));
  EXPECT_EQ(wrap_counter(-(1 << 23) - 1, 24), (1 << 23) - 1);
  EXPECT_EQ(wrap_counter(5 * (1LL << 24) + 17, 24), 17);
}

TEST(Encoder, UnwrapperFollowsACounterAcrossManyWraps) {
  std::mt19937_64 rng(1);
  std::uniform_int_distribution<int> step(-300000, 300000);  // < 2^23 between readings
  CounterUnwrapper unwrap(24);
  std::int64_t truth = (1 << 23) - 10;
  EXPECT_EQ(unwrap.update(wrap_counter(truth, 24)), truth);
  for (int k = 0; k < 20000; ++k) {
    truth += step(rng) + 20;  // drifts through many wraps
    ASSERT_EQ(unwrap.update(wrap_counter(truth, 24)), truth) << k;
  }
  EXPECT_GT(std::abs(truth), 1LL << 24);
}

TEST(Motor, Spidar8DriveChain) {
  const MotorModel m;  // SPIDAR-8 defaults
  EXPECT_NEAR(volts_per_newton(m), 0.5776, 1e-4);
  EXPECT_NEAR(max_drive_tension(m), 10.0 / 0.57762, 1e-3);
  const auto c = tension_to_command(m, 5.0);
  EXPECT_FALSE(c.saturated);
  EXPECT_NEAR(c.volts, 5.0 * volts_per_newton(m), 10.0 / 4095);
  EXPECT_NEAR(c.current, c.volts * 0.5, 1e-12);
  EXPECT_NEAR(command_to_tension(m, c.dac), 5.0, 0.5 * 10.0 / 4095 / volts_per_newton(m) + 1e-12);
}

TEST(Motor, SaturatesAtTheDacRange) {
  const MotorModel m;
  auto hi = tension_to_command(m, 30.0);
  EXPECT_TRUE(hi.saturated);
  EXPECT_EQ(hi.dac, 4095);
  EXPECT_NEAR(command_to_tension(m, hi.dac), max_drive_tension(m), 1e-12);
  auto neg = tension_to_command(m, -1.0);
  EXPECT_TRUE(neg.saturated);
  EXPECT_EQ(neg.dac, 0);
  auto nan = tension_to_command(m, std::nan(""));
  EXPECT_EQ(nan.dac, 0);
  EXPECT_EQ(command_to_tension(m, 99999), max_drive_tension(m));
  EXPECT_EQ(command_to_tension(m, -5), 0.0);
}

TEST(Motor, CommandRoundTripWithinOneDacStep) {
  const MotorModel m;
  const double step_n = 10.0 / 4095 / volts_per_newton(m);
  for (double t = 0.0; t < max_drive_tension(m); t += 0.173) {
    EXPECT_NEAR(command_to_tension(m, tension_to_command(m, t).dac), t, 0.5 * step_n + 1e-12);
  }
}

}  // namespace
}  // namespace spidar::strings
