// Hand sizes: default proportions, scaling, validation and configs/hands.yaml.
#include <gtest/gtest.h>

#include <string>

#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/hand_shape.hpp"
#include "spidar/hand/kinematics.hpp"

namespace spidar::hand {
namespace {

constexpr double kUnit = 0.0959;  // the paper's segment unit of a 0.19 m hand

TEST(HandShape, DefaultProportionsFromFacts) {
  const HandShape& s = default_hand_shape();
  EXPECT_DOUBLE_EQ(s.dimensions.length, 0.19);
  EXPECT_DOUBLE_EQ(s.dimensions.width, 0.085);
  const double expected[5][4] = {{0.390, 0.311, 0.232, 0.0},
                                 {0.66, 0.366, 0.232, 0.202},
                                 {0.645, 0.404, 0.248, 0.210},
                                 {0.58, 0.366, 0.226, 0.187},
                                 {0.52, 0.278, 0.176, 0.158}};
  for (int f = 0; f < kFingerCount; ++f) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(s.digits[f].length[k], expected[f][k] * kUnit, 1e-12) << f << " " << k;
    }
    // Digit frames are rotations: y along the digit, z dorsal.
    const Mat3& R = s.digits[f].R_H_digit;
    EXPECT_LT((R.transpose() * R - Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  }
  // Metacarpals from base to MCP have their length; MCPs are ordered thumb side → little.
  for (int f = kIndex; f <= kLittle; ++f) {
    const auto& d = s.digits[f];
    EXPECT_NEAR((d.p_H_mcp - d.p_H_base).norm(), d.length[0], 1e-12);
    if (f > kIndex) {
      EXPECT_GT(d.p_H_mcp.x(), s.digits[f - 1].p_H_mcp.x());
    }
  }
  EXPECT_LT(s.digits[kThumb].p_H_base.x(), s.digits[kIndex].p_H_mcp.x());
  // Palm breadth across the MCPs ≈ the width.
  const double breadth = (s.digits[kLittle].p_H_mcp.x() + s.digits[kLittle].radius[0]) -
                         (s.digits[kIndex].p_H_mcp.x() - s.digits[kIndex].radius[0]);
  EXPECT_NEAR(breadth, 0.085, 0.01);
}

TEST(HandShape, LengthScalesDigitsWidthScalesAcross) {
  const HandShape& a = default_hand_shape();
  const HandShape b = make_hand_shape({0.21, 0.085, Vec3(0, -0.008, 0)}).value();
  const HandShape c = make_hand_shape({0.19, 0.095, Vec3(0, -0.008, 0)}).value();
  for (int f = 0; f < kFingerCount; ++f) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(b.digits[f].length[k], a.digits[f].length[k] * 0.21 / 0.19, 1e-12);
      EXPECT_NEAR(c.digits[f].length[k], a.digits[f].length[k], 1e-12);
      EXPECT_NEAR(c.digits[f].radius[k], a.digits[f].radius[k] * 0.095 / 0.085, 1e-12);
    }
  }
  EXPECT_NEAR(c.digits[kLittle].p_H_mcp.x(), a.digits[kLittle].p_H_mcp.x() * 0.095 / 0.085, 1e-12);
  // The hand length is wrist → middle tip with straight fingers, for any size.
  for (const HandShape* s : {&a, &b, &c}) {
    HandModel m = default_hand_model(Side::kRight);
    m.shape = *s;
    const auto pts = forward_kinematics(m, HandParams{});
    EXPECT_NEAR(pts.p_W_joint[joint_index(kMiddle, 3)].y(), s->dimensions.length, 1e-12);
    EXPECT_NEAR(pts.p_W_joint[joint_index(kMiddle, 3)].x(), 0.0, 1e-12);
  }
}

TEST(HandShape, ValidationNamesTheField) {
  EXPECT_TRUE(validate_dimensions({}).ok());
  auto expect_error = [](HandDimensions d, const std::string& field) {
    const auto s = make_hand_shape(d);
    ASSERT_FALSE(s.ok()) << field;
    EXPECT_NE(s.error().message.find(field), std::string::npos) << s.error().message;
  };
  expect_error({0.019, 0.085, Vec3::Zero()}, "length");  // centimetres for metres
  expect_error({0.19, 0.2, Vec3::Zero()}, "width");
  expect_error({0.25, 0.06, Vec3::Zero()}, "width/length");
  expect_error({0.19, 0.085, Vec3(0, -8, 0)}, "fingertip_offset");
  expect_error({0.19, 0.085, Vec3(0, std::numeric_limits<double>::quiet_NaN(), 0)},
               "fingertip_offset");
  EXPECT_FALSE(make_hand_model(Side::kLeft, {0.3, 0.1, Vec3::Zero()}).ok());
  expect_error({0.19, 0.085, Vec3(0, -0.008, 0), 2.0}, "thickness");
  expect_error({0.19, 0.085, Vec3(0, -0.008, 0), std::numeric_limits<double>::quiet_NaN()}, "thickness");
}

// The digits' thickness scales their capsule radii and nothing else: not the segment lengths, the
// joints' places or the palm box.
TEST(HandShape, ThicknessScalesTheDigitsRadiiOnly) {
  const HandShape base = make_hand_shape({}).value();
  const HandShape thick = make_hand_shape({0.19, 0.085, Vec3(0, -0.008, 0), 1.25}).value();
  for (int f = 0; f < kFingerCount; ++f) {
    for (int k = 0; k < 4; ++k) {
      EXPECT_DOUBLE_EQ(thick.digits[f].radius[k], 1.25 * base.digits[f].radius[k]) << f << " " << k;
      EXPECT_DOUBLE_EQ(thick.digits[f].length[k], base.digits[f].length[k]);
    }
    EXPECT_TRUE(thick.digits[f].p_H_mcp.isApprox(base.digits[f].p_H_mcp));
  }
  EXPECT_TRUE(thick.palm.p_H_centre.isApprox(base.palm.p_H_centre));
  EXPECT_TRUE(thick.palm.half_extents.isApprox(base.palm.half_extents));
}

TEST(HandConfig, LoadsTheShippedFile) {
  const auto profiles = load_hand_profiles(SPIDAR_SOURCE_DIR "/configs/hands.yaml");
  ASSERT_EQ(profiles.profiles.size(), 2u);
  const HandProfile* model = profiles.find("model");
  const HandProfile* user = profiles.find("user");
  ASSERT_NE(model, nullptr);
  ASSERT_NE(user, nullptr);
  EXPECT_EQ(profiles.find("nobody"), nullptr);
  EXPECT_DOUBLE_EQ(model->dimensions.length, 0.19);
  EXPECT_DOUBLE_EQ(model->dimensions.width, 0.085);
  EXPECT_EQ(model->coupling, Coupling::kPaperQuadratic);
  // The model profile is the default hand.
  const HandModel m = model->model(Side::kRight);
  const HandModel d = default_hand_model(Side::kRight);
  EXPECT_EQ(m.limits.upper, d.limits.upper);
  const auto pm = forward_kinematics(m, HandParams{});
  const auto pd = forward_kinematics(d, HandParams{});
  for (int j = 0; j < kJointCount; ++j) EXPECT_EQ(pm.p_W_joint[j], pd.p_W_joint[j]);
  // The user differs by a few percent.
  const double dl = user->dimensions.length / model->dimensions.length - 1.0;
  const double dw = user->dimensions.width / model->dimensions.width - 1.0;
  EXPECT_GT(std::abs(dl), 0.01);
  EXPECT_LT(std::abs(dl), 0.1);
  EXPECT_GT(std::abs(dw), 0.01);
  EXPECT_LT(std::abs(dw), 0.1);
  EXPECT_NEAR(user->ranges.mcp_abduction.hi, units::deg_to_rad(18.0), 1e-12);
  EXPECT_EQ(user->model(Side::kLeft).side, Side::kLeft);
}

// The README's other users (configs/users/): each loads, and lies at the corner of the issue's
// ±10 % box around the model hand that its name says (length, width), with its coupling.
TEST(HandConfig, TheShippedUsersAreTheirCornersOfTheTenPercentBox) {
  const HandProfile model = *load_hand_profiles(SPIDAR_SOURCE_DIR "/configs/hands.yaml").find("model");
  struct Expected {
    const char* file;
    double length, width;  // relative to the model
    Coupling coupling;
  };
  for (const Expected& e : {Expected{"large", 0.1, 0.1, Coupling::kLinear}, Expected{"small", -0.1, -0.1, Coupling::kPaperQuadratic},
                            Expected{"short-wide", -0.1, 0.1, Coupling::kLinear},
                            Expected{"long-narrow", 0.1, -0.1, Coupling::kLinear}}) {
    const auto profiles = load_hand_profiles(std::string(SPIDAR_SOURCE_DIR "/configs/users/") + e.file + ".yaml");
    ASSERT_EQ(profiles.profiles.size(), 1u) << e.file;
    const HandProfile& u = profiles.profiles[0];
    EXPECT_EQ(u.name, e.file);
    EXPECT_NEAR(u.dimensions.length / model.dimensions.length - 1.0, e.length, 1e-3) << e.file;
    EXPECT_NEAR(u.dimensions.width / model.dimensions.width - 1.0, e.width, 1e-3) << e.file;
    EXPECT_EQ(u.coupling, e.coupling) << e.file;
  }
}

// Parses `text` as "hands.yaml" and returns the error message (empty if it parsed).
std::string error_of(const std::string& text) {
  try {
    parse_hand_profiles(core::ConfigNode::Parse(text, "hands.yaml"));
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(HandConfig, ErrorsNameFileLineAndKey) {
  const std::string good =
      "hands:\n"
      "  - name: a\n"
      "    length: 0.19\n"
      "    width: 0.085\n";
  EXPECT_EQ(error_of(good), "");

  std::string msg = error_of(
      "hands:\n"
      "  - name: a\n"
      "    length: 0.19\n"
      "    width: 0.85\n");
  EXPECT_NE(msg.find("hands.yaml:4: hands[0].width: expected a value in [0.05, 0.13] m"),
            std::string::npos)
      << msg;

  msg = error_of(
      "hands:\n"
      "  - name: a\n"
      "    length: 0.19\n"
      "    width: 0.085\n"
      "  - name: b\n"
      "    width: 0.085\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[1]: missing required key 'length'"), std::string::npos)
      << msg;

  msg = error_of(good + "    lenght: 0.2\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[0].lenght: unknown key"), std::string::npos) << msg;

  msg = error_of(good + "    coupling: cubic\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[0].coupling: expected 'quadratic' or 'linear'"),
            std::string::npos)
      << msg;

  msg = error_of(good + "    fingertip_offset: [0, -8, 0]\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[0].fingertip_offset: expected an offset of at most"),
            std::string::npos)
      << msg;

  msg = error_of(good + "    thickness: 12\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[0].thickness: expected a value in [0.6, 1.6]"), std::string::npos)
      << msg;

  msg = error_of(good + "    fingertip_offset: [0, -0.008]\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[0].fingertip_offset: expected 3 numbers, got 2"),
            std::string::npos)
      << msg;

  msg = error_of(good +
                 "    joint_ranges_deg:\n"
                 "      pip_flexion: [110, 0]\n");
  EXPECT_NE(msg.find("hands.yaml:6: hands[0].joint_ranges_deg.pip_flexion: expected lo < hi"),
            std::string::npos)
      << msg;

  msg = error_of(good +
                 "    joint_ranges_deg:\n"
                 "      dip_flexion: [-10, 90]\n");
  EXPECT_NE(msg.find("hands.yaml:6: hands[0].joint_ranges_deg: joint range dip_flexion"),
            std::string::npos)
      << msg;

  msg = error_of(good + "  - name: a\n    length: 0.2\n    width: 0.09\n");
  EXPECT_NE(msg.find("hands.yaml:5: hands[1].name: duplicate hand profile name 'a'"),
            std::string::npos)
      << msg;

  msg = error_of("hands: []\n");
  EXPECT_NE(msg.find("hands.yaml:1: hands: expected at least one hand profile"), std::string::npos)
      << msg;

  msg = error_of(
      "hands:\n"
      "  - name: a\n"
      "    length: 0.25\n"
      "    width: 0.06\n");
  EXPECT_NE(msg.find("hands.yaml:4: hands[0].width: expected width/length in [0.3, 0.65]"),
            std::string::npos)
      << msg;
}

TEST(HandConfig, MissingFileSaysSo) {
  try {
    load_hand_profiles("/nonexistent/hands.yaml");
    FAIL() << "expected a ConfigError";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/hands.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos);
  }
}

}  // namespace
}  // namespace spidar::hand
