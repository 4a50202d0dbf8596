// The string calibration procedure on the simulated SPIDAR-8: the simulated user, pole
// calibration fixing wrong offsets, and a multi-point jig over counters that wrap (the procedure
// must unwrap them as the servo cycle does).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "device_test_support.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/device/string_calibration.hpp"
#include "spidar/strings/calibration.hpp"

namespace spidar::device {
namespace {

using testing::spidar8;

TEST(CalibrationUser, BringsTheActiveFingerToTheTargetOthersKeepMoving) {
  CalibrationUser user(spidar8(), 0.5);
  user.activate(3, Vec3(0.01, 0, 0), 1.0);
  std::vector<Vec3> a(8), b(8);
  user.goals(1.6, a);
  user.goals(1.8, b);
  EXPECT_NEAR((a[3] - Vec3(0.01, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((b[3] - Vec3(0.01, 0, 0)).norm(), 0.0, 1e-12);
  EXPECT_GT((a[0] - b[0]).norm(), 1e-3);  // hovering
}

/// Runs the procedure on a simulated device whose counters were zeroed with the fingertips at
/// the frame centre (`truth` config), while `believed` is the calibration in use.
struct SimRun {
  strings::DeviceConfig truth, believed;
  SimulatedSpidarParams params;
  std::vector<std::string> lines;

  Result<std::vector<FingerCalibration>> run(const StringCalibrationParams& p) {
    auto user = std::make_shared<CalibrationUser>(truth);
    params.fixed_step_s = 1e-3;
    SimulatedSpidar sim(truth, params, user);
    EXPECT_TRUE(sim.open().ok());
    std::uint64_t cycle = 0;
    CalibrationClock clock{[&] { return static_cast<double>(cycle) * 1e-3; }, [&] { ++cycle; }};
    auto r = calibrate_strings(
        sim, believed, p, clock, [&](const std::string& l) { lines.push_back(l); },
        [&](int f, const Vec3& target, double t) { user->activate(f, target, t); });
    sim.close();
    return r;
  }
  /// RMS position error [m] of finger f's channels over a grid, against the simulated device's
  /// true channels (its counters read 0 with the fingertip at the frame centre).
  double error_m(int f, const std::vector<strings::EncoderChannel>& ch) const {
    const auto& fc = truth.fingers[static_cast<std::size_t>(f)];
    std::vector<strings::EncoderChannel> true_channels = fc.channels;
    for (int i = 0; i < fc.geometry.n; ++i)
      true_channels[static_cast<std::size_t>(i)].length_at_zero =
          (fc.geometry.p_WA[i] - truth.p_W_centre).norm();
    const auto e = strings::position_error_rms(fc.geometry, true_channels, ch,
                                               strings::jig_grid(truth.p_W_centre, 0.05, 3));
    EXPECT_TRUE(e.ok());
    return e.ok() ? *e : 1e9;
  }
};

bool any_line_has(const std::vector<std::string>& lines, const std::string& part) {
  for (const auto& l : lines)
    if (testing::contains(l, part)) return true;
  return false;
}

TEST(StringCalibration, PoleFixesOffsetsCentimetresOff) {
  SimRun r{spidar8(), spidar8(), {}, {}};
  for (auto& c : r.believed.fingers[1].channels) c.length_at_zero += 0.03;  // left_index
  StringCalibrationParams p;
  p.fingers = {1};
  p.stability.near_m = 1e9;  // the present calibration is centimetres off
  ASSERT_GT(r.error_m(1, r.believed.fingers[1].channels), 0.02);
  const auto result = r.run(p);
  ASSERT_TRUE(result.ok()) << result.error().message;
  ASSERT_EQ(result->size(), 1u);
  const FingerCalibration& fr = result->front();
  EXPECT_EQ(fr.finger, 1);
  ASSERT_TRUE(fr.pole_error_after_m.has_value());
  EXPECT_LT(*fr.pole_error_after_m, 1e-4);  // by construction
  EXPECT_GT(*fr.pole_error_before_m, 0.02);
  // Held by hand, the minimum tensions pull the cap a few millimetres off the pole tip.
  EXPECT_LT(r.error_m(1, fr.channels), 0.005);
  EXPECT_TRUE(any_line_has(r.lines, "left_index: touch the pole tip")) << r.lines.front();
  EXPECT_TRUE(any_line_has(r.lines, "sampled after holding"));
}

TEST(StringCalibration, JigOverWrappingCountersFitsScaleAndOffset) {
  // 10-bit counters wrap every 1024 counts (3 cm of string): moving between jig points 4 cm
  // apart wraps them, and raw readings would give nonsense slopes.
  SimRun r{spidar8(), spidar8(), {}, {}};
  r.truth.counter_bits = r.believed.counter_bits = 10;
  r.params.impedance.stiffness = 20000;  // clamped in the jig
  r.params.impedance.damping =
      2 * std::sqrt(r.params.impedance.stiffness * r.params.impedance.mass);
  StringCalibrationParams p;
  p.fingers = {4};
  p.jig = 2;
  p.jig_spacing_m = 0.04;
  p.stability.hold_s = 0.3;
  p.stability.near_m = 1e9;
  const auto result = r.run(p);
  ASSERT_TRUE(result.ok()) << result.error().message;
  const FingerCalibration& fr = result->front();
  ASSERT_EQ(fr.channels.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(fr.residual_rms_m[static_cast<std::size_t>(i)], 1e-4) << i;
    EXPECT_NEAR(fr.channels[static_cast<std::size_t>(i)].metres_per_count, 2.924e-5,
                0.005 * 2.924e-5)
        << i;
  }
  EXPECT_TRUE(any_line_has(r.lines, "jig point 8/8"));
}

TEST(StringCalibration, AFingertipThatNeverHoldsStillTimesOutNamingTheFinger) {
  SimRun r{spidar8(), spidar8(), {}, {}};
  StringCalibrationParams p;
  p.fingers = {2};
  p.stability.tolerance_m = 1e-7;  // below the encoder noise: never still
  p.timeout_s = 1.0;
  const auto result = r.run(p);
  ASSERT_FALSE(result.ok());
  EXPECT_TRUE(testing::contains(result.error().message, "left_middle")) << result.error().message;
  EXPECT_TRUE(testing::contains(result.error().message, "did not hold still"))
      << result.error().message;
  p.fingers = {12};
  const auto bad = r.run(p);
  ASSERT_FALSE(bad.ok());
  EXPECT_TRUE(testing::contains(bad.error().message, "no finger 12")) << bad.error().message;
}

}  // namespace
}  // namespace spidar::device
