#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "spidar/strings/device_config.hpp"
#include "test_support.hpp"

namespace spidar::strings {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string parse_error(const std::string& text, const std::string& name = "configs/spidar8.yaml") {
  try {
    parse_device_config(core::ConfigNode::Parse(text, name));
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

/// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  return pos == std::string::npos ? -1 : 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
}

TEST(DeviceConfig, Spidar8LoadsWithTheMappedFulcrumTable) {
  const auto& cfg = testing::spidar8();
  EXPECT_EQ(cfg.name, "SPIDAR-8");
  ASSERT_EQ(cfg.fingers.size(), 8u);
  EXPECT_EQ(cfg.string_count(), 24);
  // Unit 0's A1 (-0.025, +0.230, -0.283) in the source axes is (-0.025, 0.283, 0.230) here.
  const auto& middle = cfg.fingers[2];
  EXPECT_EQ(middle.name, "left_middle");
  EXPECT_EQ(middle.unit, 0);
  EXPECT_TRUE(middle.geometry.p_WA[0].isApprox(Vec3(-0.025, 0.283, 0.230)));
  // Right hand mirrors the left in x, finger by finger.
  for (int k = 0; k < 4; ++k) {
    const auto& l = cfg.fingers[k];
    const auto& r = cfg.fingers[k + 4];
    EXPECT_EQ(l.hand, "left");
    EXPECT_EQ(r.hand, "right");
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(r.geometry.p_WA[i].isApprox(Vec3(-1, 1, 1).asDiagonal() * l.geometry.p_WA[i]));
    }
  }
  // Counters are zeroed at the pole by default: length at count 0 is the pole distance.
  EXPECT_NEAR(cfg.fingers[0].channels[0].length_at_zero, cfg.fingers[0].geometry.p_WA[0].norm(), 1e-15);
  EXPECT_NEAR(cfg.effective_limits().t_max, 17.31, 0.01);
  EXPECT_EQ(cfg.effective_limits().t_min, 0.35);
}

TEST(DeviceConfig, G4HasFourStringsToOnePoint) {
  const auto& cfg = testing::spidar_g4();
  ASSERT_EQ(cfg.fingers.size(), 1u);
  EXPECT_EQ(cfg.fingers[0].geometry.n, 4);
}

TEST(DeviceConfig, ShortFulcrumNamesFileLineAndKey) {
  std::string text = read_file(testing::source_path("configs/spidar8.yaml"));
  // Drop the last number of fingers[3].fulcrums[1] (left_ring, second fulcrum).
  const std::string target = "- [-0.316, -0.283, 0.025]";
  const int line = line_of(text, target);
  ASSERT_GT(line, 0);
  text.replace(text.find(target), target.size(), "- [-0.316, -0.283]");
  EXPECT_EQ(parse_error(text), "configs/spidar8.yaml:" + std::to_string(line) +
                                   ": fingers[3].fulcrums[1]: expected 3 numbers, got 2");
}

TEST(DeviceConfig, DegenerateLayoutsAreRejectedWhereTheyAre) {
  std::string base = read_file(testing::source_path("configs/spidar-g4.yaml"));
  const int line = line_of(base, "fulcrums:");
  std::string collinear = base;
  collinear.replace(collinear.find("fulcrums:"), std::string::npos,
                    "fulcrums: [[0, 0, 0.3], [0.1, 0, 0.3], [0.2, 0, 0.3], [0.3, 0, 0.3]]\n");
  EXPECT_EQ(parse_error(collinear, "g4.yaml").rfind("g4.yaml:" + std::to_string(line) +
                                                        ": fingers[0].fulcrums: fulcrums are collinear",
                                                    0),
            0u)
      << parse_error(collinear, "g4.yaml");
  std::string coincident = base;
  coincident.replace(coincident.find("fulcrums:"), std::string::npos,
                     "fulcrums: [[0, 0, 0.3], [0, 0, 0.3], [0.2, 0, 0.3]]\n");
  EXPECT_NE(parse_error(coincident).find("fulcrums 0 and 1 coincide"), std::string::npos);
}

TEST(DeviceConfig, OtherMistakesGiveClearErrors) {
  const std::string g4 = read_file(testing::source_path("configs/spidar-g4.yaml"));
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = g4;
    const auto pos = t.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    t.replace(pos, from.size(), to);
    return parse_error(t, "g4.yaml");
  };
  EXPECT_NE(with("min: 0.35", "min: -1").find("tension.min: expected a tension >= 0 N"),
            std::string::npos);
  EXPECT_NE(with("max: 30.0", "max: 0.1").find("tension.max: expected max > min"), std::string::npos);
  EXPECT_NE(with("  - name: grip\n", "  - name: grip\n    signs: [1, 1, 2, 1]\n")
                .find("fingers[0].signs[2]: expected +1 or -1"),
            std::string::npos);
  EXPECT_NE(with("  - name: grip\n", "  - name: grip\n    signs: [1, 1]\n")
                .find("fingers[0].signs: expected 4 numbers (one per string), got 2"),
            std::string::npos);
  EXPECT_NE(with("counter_bits: 24", "counter_bits: 24\n  bogus: 1").find("encoder.bogus: unknown key"),
            std::string::npos);
  EXPECT_NE(with("metres_per_count: 2.513e-5", "metres_per_count: abc")
                .find("encoder.metres_per_count: expected a number, got 'abc'"),
            std::string::npos);
  EXPECT_NE(with("torque_constant: 0.0277", "torque_constant: 0")
                .find("motor.torque_constant: expected a positive number"),
            std::string::npos);
  EXPECT_NE(with("name: SPIDAR-G4\n", "").find("missing required key 'name'"), std::string::npos);
  // Integers beyond int's range are refused as written, not wrapped into range (4294967320 is
  // 24 + 2^32).
  EXPECT_NE(with("counter_bits: 24", "counter_bits: 4294967320").find("encoder.counter_bits: expected 8..62, got 4294967320"),
            std::string::npos);
  EXPECT_NE(with("dac_bits: 12", "dac_bits: 4294967308").find("motor.dac_bits: expected 1..24, got 4294967308"),
            std::string::npos);
  // The encoder's resolution at the top of its range is taken, by the fingers too (it was refused
  // at a finger's key it did not have); a finger's own value out of range is named at its key.
  EXPECT_EQ(with("metres_per_count: 2.513e-5", "metres_per_count: 0.01"), "no error");
  EXPECT_NE(with("  - name: grip\n", "  - name: grip\n    metres_per_count: [1e-5, 1e-5, 0.02, 1e-5]\n")
                .find("fingers[0].metres_per_count[2]: expected a value in [1e-09, 0.01] m, got 0.02"),
            std::string::npos);
  EXPECT_NE(with("name: SPIDAR-G4", "name: \"\"").find("name: expected a non-blank device name, got ''"), std::string::npos);
  // A DAC range whose span would overflow (1.7e308 − (−1.7e308)).
  EXPECT_NE(with("dac_v_min: ", "dac_v_min: -1.7e308 #").find("motor.dac_v_min: expected a value in [-1000, 1000] V"),
            std::string::npos);
  // A name that is not UTF-8 is refused where it is read (it would break the JSON written later).
  EXPECT_NE(with("name: SPIDAR-G4", "name: SPIDAR\xFF").find("name: expected UTF-8 text, got byte 0xFF at offset 6"),
            std::string::npos);
  std::string two = g4 + "  - name: grip\n    fulcrums: [[0, 0, 0.3], [0.2, 0, 0.3], [0, 0.2, 0.3]]\n";
  EXPECT_NE(parse_error(two).find("duplicate finger name 'grip'"), std::string::npos);
}

// Ranges a hostile or careless config got past the loader (issue 17): units, names, how many
// fingers and strings, and where the frame centre is.
TEST(DeviceConfig, UnitsNamesCountsAndTheFrameCentreAreChecked) {
  const std::string s8 = read_file(testing::source_path("configs/spidar8.yaml"));
  auto with = [&](const std::string& from, const std::string& to) {
    std::string t = s8;
    const auto pos = t.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    t.replace(pos, from.size(), to);
    return parse_error(t, "s8.yaml");
  };
  EXPECT_NE(with("unit: 3\n", "unit: 2\n").find("fingers[1].unit: unit 2 is also finger 0's ('left_thumb'); expected one unit per finger"),
            std::string::npos) << with("unit: 3\n", "unit: 2\n");
  EXPECT_NE(with("unit: 3\n", "unit: 99\n").find("fingers[1].unit: expected a unit number 0..7 (one per fingertip), got 99"),
            std::string::npos) << with("unit: 3\n", "unit: 99\n");
  EXPECT_NE(with("unit: 3\n", "unit: -1\n").find("got -1"), std::string::npos);
  EXPECT_NE(with("name: left_index", "name: \"\"").find("fingers[1].name: expected a non-blank finger name, got ''"),
            std::string::npos) << with("name: left_index", "name: \"\"");
  const std::string far = with("frame_centre: [0.0, 0.0, 0.0]", "frame_centre: [100.0, 0.0, 0.0]");
  EXPECT_NE(far.find("s8.yaml:"), std::string::npos) << far;
  EXPECT_NE(far.find("frame_centre: the frame centre (100, 0, 0) m is not inside the fulcrums' convex hull"),
            std::string::npos) << far;
  // Just inside the frame (the fulcrums reach x = ±0.366 m) is fine.
  EXPECT_EQ(with("frame_centre: [0.0, 0.0, 0.0]", "frame_centre: [0.3, 0.0, 0.0]"), "no error");

  // A ninth finger, and more strings than the protocol carries.
  const std::string g4 = read_file(testing::source_path("configs/spidar-g4.yaml"));
  std::string nine = g4;
  for (int i = 0; i < 8; ++i)
    nine += "  - name: extra" + std::to_string(i) + "\n    fulcrums: [[-0.3, -0.3, -0.3], [0.3, -0.3, -0.3], [0, 0.3, -0.3], [0, 0, 0.3]]\n";
  EXPECT_NE(parse_error(nine).find("fingers: expected at most 8 fingers, got 9"), std::string::npos) << parse_error(nine);
  std::string many = g4;
  for (int i = 0; i < 7; ++i)
    many += "  - name: extra" + std::to_string(i) + "\n    fulcrums: [[-0.3, -0.3, -0.3], [0.3, -0.3, -0.3], [0, 0.3, -0.3], [0, 0, 0.3], [0.1, 0.1, 0.3]]\n";
  EXPECT_NE(parse_error(many).find("fingers[6].fulcrums: this finger brings the device to 34 strings; expected at most 32 in all (the wire protocol's limit)"),
            std::string::npos) << parse_error(many);
}

TEST(DeviceConfig, MissingFileIsAClearError) {
  try {
    load_device_config("/no/such/spidar.yaml");
    FAIL();
  } catch (const core::ConfigError& e) {
    EXPECT_STREQ(e.what(), "/no/such/spidar.yaml: cannot open file (does it exist and is it readable?)");
  }
}

}  // namespace
}  // namespace spidar::strings
