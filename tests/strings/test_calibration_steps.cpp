// The calibration steps' pure parts: the stability check on a finger's counts, and writing
// calibrated channels back into a device config's YAML text and file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "temp_path.hpp"
#include "spidar/core/config.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/device_config_write.hpp"
#include "spidar/strings/stability_check.hpp"
#include "test_support.hpp"

namespace spidar::strings {
namespace {

namespace fs = std::filesystem;
using testing::source_path;
using testing::spidar8;

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

/// The counts an ideal encoder of each of a finger's strings reads with the fingertip at p (its
/// calibration channels, rounded to whole counts).
std::vector<std::int64_t> counts_at(const FingerConfig& f, const Vec3& p) {
  std::vector<std::int64_t> c;
  for (int i = 0; i < f.geometry.n; ++i)
    c.push_back(length_to_counts(f.channels[i], (f.geometry.p_WA[i] - p).norm()));
  return c;
}

TEST(StabilityCheck, SamplesOnlyAfterHoldingStillNearTheTarget) {
  const auto& cfg = spidar8();
  const auto& f = cfg.fingers[1];
  StabilityParams p;  // 0.5 s, 0.5 mm, 30 mm
  StabilityCheck still(f, Vec3::Zero(), p);
  double t = 0;
  for (; t < 0.49; t += 0.001) {
    still.update(t, counts_at(f, Vec3(0.002, 0, 0)));
    ASSERT_FALSE(still.ready()) << t;
  }
  for (; t < 0.52; t += 0.001) still.update(t, counts_at(f, Vec3(0.002, 0, 0)));
  EXPECT_TRUE(still.ready());
  EXPECT_NEAR(still.distance_m(), 0.002, 1e-4);
  const auto s = still.sample();
  const auto expect = counts_at(f, Vec3(0.002, 0, 0));
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_EQ(s[i], expect[i]);

  // Moving 2 mm back and forth every 0.2 s: never still long enough.
  StabilityCheck moving(f, Vec3::Zero(), p);
  for (t = 0; t < 3; t += 0.001)
    moving.update(t, counts_at(f, Vec3(0.002 * (static_cast<int>(t / 0.2) % 2), 0, 0)));
  EXPECT_FALSE(moving.ready());
  // Still, but 5 cm from the pole: not the pole.
  StabilityCheck far(f, Vec3::Zero(), p);
  for (t = 0; t < 2; t += 0.001) far.update(t, counts_at(f, Vec3(0.05, 0, 0)));
  EXPECT_FALSE(far.ready());
  EXPECT_NEAR(far.distance_m(), 0.05, 1e-4);
}

TEST(ConfigWriteBack, ReplacesTheFingersChannelsAndKeepsTheRest) {
  const std::string text = slurp(source_path("configs/spidar8.yaml"));
  std::vector<EncoderChannel> ch = {{1, 3e-5, 0.41}, {-1, 2.9e-5, 0.42}, {1, 2.95e-5, 0.43}};
  std::string out =
      with_finger_channels(text, "spidar8.yaml", "left_ring", ch, false, "pole calibration");
  out = with_finger_channels(out, "spidar8.yaml", "left_ring", ch, true,
                             "jig");  // replaces, no duplicates
  const auto cfg = parse_device_config(core::ConfigNode::Parse(out, "out.yaml"));
  const auto& orig = spidar8();
  for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const auto& c = cfg.fingers[f].channels[i];
      const auto& o = cfg.fingers[f].name == "left_ring" ? ch[i] : orig.fingers[f].channels[i];
      EXPECT_EQ(c.sign, o.sign) << f << " " << i;
      EXPECT_NEAR(c.metres_per_count, o.metres_per_count, 1e-15);
      EXPECT_NEAR(c.length_at_zero, o.length_at_zero, 1e-12);
    }
  }
  EXPECT_NE(out.find("# SPIDAR-8: eight fingertips"), std::string::npos);  // comments kept
  EXPECT_EQ(out.find("length_at_zero"), out.rfind("length_at_zero"));      // one block, once
  EXPECT_THROW(with_finger_channels(text, "spidar8.yaml", "left_pinky", ch, false, ""),
               SpidarError);
}

TEST(ConfigWriteBack, KeepsThePreviousVersionAndRefusesABrokenConfig) {
  const fs::path d = fs::path(spidar::test::scratch_path("spidar_wb"));
  fs::remove_all(d);
  fs::create_directories(d);
  const fs::path p = d / "dev.yaml";
  fs::copy_file(source_path("configs/spidar8.yaml"), p);
  const std::string before = slurp(p);
  std::vector<EncoderChannel> ch = {{1, 2.924e-5, 0.40}, {1, 2.924e-5, 0.41}, {1, 2.924e-5, 0.42}};
  const std::string backup = write_device_config(
      p.string(), with_finger_channels(before, "x", "right_thumb", ch, false, "n"));
  EXPECT_EQ(slurp(backup), before);
  EXPECT_EQ(load_device_config(p.string()).fingers[4].channels[2].length_at_zero, 0.42);
  const std::string now = slurp(p);
  EXPECT_THROW(write_device_config(p.string(), "fingers: 3\n"), SpidarError);
  EXPECT_EQ(slurp(p), now);  // untouched
}

}  // namespace
}  // namespace spidar::strings
