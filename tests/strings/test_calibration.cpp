#include <gtest/gtest.h>

#include "spidar/strings/calibration.hpp"
#include "spidar/strings/position.hpp"
#include "test_support.hpp"

namespace spidar::strings {
namespace {

/// A simulated device whose true channels differ from the config: per-string scale error and
/// arbitrary power-up counts.
std::vector<EncoderChannel> true_channels(const FingerConfig& f, std::mt19937_64& rng) {
  std::normal_distribution<double> scale(1.0, 0.02);
  std::uniform_int_distribution<std::int64_t> power_up(-2000000, 2000000);
  std::vector<EncoderChannel> out;
  for (int i = 0; i < f.geometry.n; ++i) {
    EncoderChannel ch = f.channels[i];
    ch.metres_per_count *= scale(rng);
    ch.length_at_zero += ch.metres_per_count * static_cast<double>(power_up(rng));
    out.push_back(ch);
  }
  return out;
}

std::vector<std::int64_t> read_counts(const PointGeometry& g, const std::vector<EncoderChannel>& truth,
                                      const Vec3& p) {
  std::vector<std::int64_t> c;
  for (int i = 0; i < g.n; ++i) c.push_back(length_to_counts(truth[i], (g.p_WA[i] - p).norm()));
  return c;
}

std::vector<Vec3> test_points(const PointGeometry& g, std::mt19937_64& rng) {
  std::vector<Vec3> pts;
  for (int k = 0; k < 500; ++k) pts.push_back(testing::random_workspace_point(g, rng, 0.08));
  return pts;
}

TEST(Calibration, PoleCalibrationIsExactAtThePole) {
  const auto& cfg = testing::spidar8();
  std::mt19937_64 rng(1);
  for (const auto& f : cfg.fingers) {
    auto truth = true_channels(f, rng);
    for (auto& ch : truth) ch.metres_per_count = f.channels[0].metres_per_count;  // scale known
    const auto counts = read_counts(f.geometry, truth, cfg.p_W_centre);
    const auto cal = pole_calibrate(f.geometry, f.channels, counts, cfg.p_W_centre).value();
    for (int i = 0; i < f.geometry.n; ++i) {
      EXPECT_NEAR(counts_to_length(cal[i], counts[i]), (f.geometry.p_WA[i] - cfg.p_W_centre).norm(),
                  1e-12);
    }
    // With the scale right, only quantisation remains anywhere in the workspace.
    EXPECT_LT(position_error_rms(f.geometry, truth, cal, test_points(f.geometry, rng)).value(),
              1e-4);
  }
}

TEST(Calibration, MultipointJigWithHalfMillimetrePlacementNoiseIsUnderOneMillimetre) {
  // The paper's manual pole calibration averaged about 5 mm; the jig fit must do < 1 mm RMS.
  const auto& cfg = testing::spidar8();
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> placement(0.0, 0.0005);
  double worst = 0, sum2 = 0;
  int runs = 0;
  for (int trial = 0; trial < 5; ++trial) {
    for (const auto& f : cfg.fingers) {
      const auto truth = true_channels(f, rng);
      std::vector<JigSample> samples;
      for (const Vec3& p : jig_grid(cfg.p_W_centre, 0.06, 3)) {
        const Vec3 placed = p + Vec3(placement(rng), placement(rng), placement(rng));
        samples.push_back({p, read_counts(f.geometry, truth, placed)});
      }
      const auto fits = fit_multipoint(f.geometry, samples).value();
      std::vector<EncoderChannel> cal;
      for (int i = 0; i < f.geometry.n; ++i) {
        cal.push_back(fits[i].channel);
        EXPECT_EQ(fits[i].channel.sign, truth[i].sign);
        EXPECT_NEAR(fits[i].channel.metres_per_count, truth[i].metres_per_count,
                    0.01 * truth[i].metres_per_count);
        EXPECT_LT(fits[i].residual_rms, 2e-3);
        EXPECT_GE(fits[i].residual_max, fits[i].residual_rms);
      }
      const double err = position_error_rms(f.geometry, truth, cal, test_points(f.geometry, rng)).value();
      worst = std::max(worst, err);
      sum2 += err * err;
      ++runs;
    }
  }
  const double rms = std::sqrt(sum2 / runs);
  ::testing::Test::RecordProperty("jig_position_error_rms_mm", std::to_string(rms * 1e3));
  ::testing::Test::RecordProperty("jig_position_error_worst_finger_mm", std::to_string(worst * 1e3));
  EXPECT_LT(rms, 1e-3);
  EXPECT_LT(worst, 1.5e-3);
}

TEST(Calibration, MultipointRecoversNoiseFreeChannelsExactly) {
  const auto& f = testing::spidar_g4().fingers[0];
  std::mt19937_64 rng(4);
  auto truth = true_channels(f, rng);
  truth[2].sign = -1;  // a string wound the other way
  std::vector<JigSample> samples;
  for (const Vec3& p : jig_grid(Vec3::Zero(), 0.05, 3))
    samples.push_back({p, read_counts(f.geometry, truth, p)});
  const auto fits = fit_multipoint(f.geometry, samples).value();
  for (int i = 0; i < f.geometry.n; ++i) {
    EXPECT_EQ(fits[i].channel.sign, truth[i].sign);
    // Quantisation (±0.5 count over a ~4000-count spread) bounds the slope to a few 1e-4.
    EXPECT_NEAR(fits[i].channel.metres_per_count, truth[i].metres_per_count, 5e-4 * truth[i].metres_per_count);
    EXPECT_LT(fits[i].residual_rms, 2e-5);  // quantisation only
  }
}

TEST(Calibration, BadSamplesAreErrors) {
  const auto& f = testing::spidar8().fingers[0];
  std::vector<JigSample> one = {{Vec3::Zero(), {1, 2, 3}}};
  EXPECT_EQ(fit_multipoint(f.geometry, one).error().message,
            "multi-point calibration: expected at least 2 jig samples, got 1");
  std::vector<JigSample> same = {{Vec3::Zero(), {1, 2, 3}}, {Vec3::Zero(), {1, 2, 3}}};
  EXPECT_NE(fit_multipoint(f.geometry, same).error().message.find("string 0"), std::string::npos);
  std::vector<JigSample> short_counts = {{Vec3::Zero(), {1, 2}}, {Vec3::Ones(), {1, 2, 3}}};
  EXPECT_NE(fit_multipoint(f.geometry, short_counts).error().message.find("sample 0"),
            std::string::npos);
  const std::vector<std::int64_t> counts = {1, 2};
  EXPECT_FALSE(pole_calibrate(f.geometry, f.channels, counts, Vec3::Zero()).ok());
}

}  // namespace
}  // namespace spidar::strings
