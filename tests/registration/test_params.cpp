// Registration settings: defaults valid, configs/registration.yaml equals the defaults, and errors
// name the key (and, when parsed, file:line).
#include <gtest/gtest.h>

#include <string>

#include "spidar/core/config.hpp"
#include "spidar/registration/registration_params.hpp"

namespace spidar::registration {
namespace {

TEST(RegistrationParams, DefaultsAreValid) { EXPECT_TRUE(validate(RegistrationParams{}).ok()); }

TEST(RegistrationParams, ValidateNamesTheField) {
  RegistrationParams p;
  p.wrist_sigma_px = 0;
  auto s = validate(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("wrist_sigma_px"), std::string::npos) << s.error().message;
  p = {};
  p.joint_ball_alpha = 1.5;
  EXPECT_NE(validate(p).error().message.find("joint_ball_alpha"), std::string::npos);
  p = {};
  p.silhouette_samples_per_bone = kMaxSilhouetteSamplesPerBone + 1;
  EXPECT_NE(validate(p).error().message.find("silhouette_samples_per_bone"), std::string::npos);
  p = {};
  p.fingertip_sigma_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate(p).error().message.find("fingertip_sigma_m"), std::string::npos);
  p = {};
  p.max_iterations = 0;
  EXPECT_NE(validate(p).error().message.find("max_iterations"), std::string::npos);
  p = {};
  p.coverage_stride_px = 0;
  EXPECT_NE(validate(p).error().message.find("coverage_stride_px"), std::string::npos);
  p = {};
  p.coverage_sigma_px = -1;
  EXPECT_NE(validate(p).error().message.find("coverage_sigma_px"), std::string::npos);
  p = {};
  p.coverage_huber_px = std::numeric_limits<double>::infinity();
  EXPECT_NE(validate(p).error().message.find("coverage_huber_px"), std::string::npos);
  p = {};
  p.digit_axis_sigma_px = -2;
  EXPECT_NE(validate(p).error().message.find("digit_axis_sigma_px"), std::string::npos);
  p.digit_axis_sigma_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate(p).error().message.find("digit_axis_sigma_px"), std::string::npos);
}

TEST(RegistrationParams, TheDetectorMidpointSwitchIsRead) {
  const auto root = core::ConfigNode::Parse("registration:\n  bracelet_detector_midpoint: true\n", "r.yaml");
  EXPECT_TRUE(parse_registration_params(root["registration"]).bracelet_detector_midpoint);
  const auto off = core::ConfigNode::Parse("registration:\n  bracelet_detector_midpoint: false\n", "r.yaml");
  EXPECT_FALSE(parse_registration_params(off["registration"]).bracelet_detector_midpoint);
}

TEST(RegistrationParams, ShippedConfigIsTheDefaults) {
  const auto root = core::ConfigNode::LoadFile(SPIDAR_SOURCE_DIR "/configs/registration.yaml");
  const RegistrationParams p = parse_registration_params(root["registration"]);
  const RegistrationParams d;
  EXPECT_EQ(p.fingertip_sigma_m, d.fingertip_sigma_m);
  EXPECT_EQ(p.wrist_sigma_px, d.wrist_sigma_px);
  EXPECT_EQ(p.bracelet_offset_m, d.bracelet_offset_m);
  EXPECT_EQ(p.bracelet_detector_midpoint, d.bracelet_detector_midpoint);
  EXPECT_EQ(p.joint_ball_sigma_px, d.joint_ball_sigma_px);
  EXPECT_EQ(p.joint_ball_alpha, d.joint_ball_alpha);
  EXPECT_EQ(p.ball_radius_scale, d.ball_radius_scale);
  EXPECT_EQ(p.matte_threshold, d.matte_threshold);
  EXPECT_EQ(p.silhouette_term, d.silhouette_term);
  EXPECT_EQ(p.silhouette_sigma_px, d.silhouette_sigma_px);
  EXPECT_EQ(p.silhouette_samples_per_bone, d.silhouette_samples_per_bone);
  EXPECT_EQ(p.silhouette_inward, d.silhouette_inward);
  EXPECT_EQ(p.coverage_sigma_px, d.coverage_sigma_px);
  EXPECT_EQ(p.coverage_stride_px, d.coverage_stride_px);
  EXPECT_EQ(p.coverage_max_px, d.coverage_max_px);
  EXPECT_EQ(p.coverage_huber_px, d.coverage_huber_px);
  EXPECT_EQ(p.digit_axis_sigma_px, d.digit_axis_sigma_px);
  EXPECT_EQ(p.little_free, d.little_free);
  EXPECT_EQ(p.little_coupling_sigma_rad, d.little_coupling_sigma_rad);
  EXPECT_EQ(p.prior_sigma_wrist_m, d.prior_sigma_wrist_m);
  EXPECT_EQ(p.prior_sigma_rotation_rad, d.prior_sigma_rotation_rad);
  EXPECT_EQ(p.prior_sigma_joint_rad, d.prior_sigma_joint_rad);
  EXPECT_EQ(p.lambda_initial, d.lambda_initial);
  EXPECT_EQ(p.max_iterations, d.max_iterations);
  EXPECT_EQ(p.cost_epsilon, d.cost_epsilon);
  EXPECT_EQ(p.step_epsilon, d.step_epsilon);
}

/// The settings parsed from a registration.yaml whose `registration:` map holds `body`.
RegistrationParams parse(const std::string& body) {
  return parse_registration_params(core::ConfigNode::Parse("registration:\n" + body, "reg.yaml")["registration"]);
}

TEST(RegistrationParams, ParsesValues) {
  const RegistrationParams p = parse("  silhouette_term: true\n  wrist_sigma_px: 6\n  max_iterations: 4\n");
  EXPECT_TRUE(p.silhouette_term);
  EXPECT_EQ(p.wrist_sigma_px, 6.0);
  EXPECT_EQ(p.max_iterations, 4);
  EXPECT_EQ(p.fingertip_sigma_m, RegistrationParams{}.fingertip_sigma_m);
  // The band's length.
  const RegistrationParams b =
      parse("  bracelet_length_sigma: 0.03\n  bracelet_length_tolerance: 0.15\n"
            "  bracelet_depth_ratio: 0.7\n  bracelet_length_min_fill: 0.5\n  bracelet_length_gate: 0.3\n");
  EXPECT_EQ(b.bracelet_length_sigma, 0.03);
  EXPECT_EQ(b.bracelet_length_tolerance, 0.15);
  EXPECT_EQ(b.bracelet_depth_ratio, 0.7);
  EXPECT_EQ(b.bracelet_length_min_fill, 0.5);
  EXPECT_EQ(b.bracelet_length_gate, 0.3);
  EXPECT_EQ(RegistrationParams{}.bracelet_length_sigma, 0.0);  // off unless asked for
  // The band's thickness.
  const RegistrationParams t =
      parse("  bracelet_width_m: 0.02\n  bracelet_thickness_sigma: 0.07\n  bracelet_thickness_tolerance: 0.25\n");
  EXPECT_EQ(t.bracelet_width_m, 0.02);
  EXPECT_EQ(t.bracelet_thickness_sigma, 0.07);
  EXPECT_EQ(t.bracelet_thickness_tolerance, 0.25);
}

std::string parse_error(const std::string& yaml) {
  try {
    (void)parse_registration_params(core::ConfigNode::Parse(yaml, "reg.yaml")["registration"]);
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(RegistrationParams, ParseErrorsNameFileLineAndKey) {
  // Out of range: the message points at the key's own line.
  std::string e = parse_error("registration:\n  wrist_sigma_px: 4\n  joint_ball_alpha: 2\n");
  EXPECT_NE(e.find("reg.yaml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("registration.joint_ball_alpha"), std::string::npos) << e;
  EXPECT_NE(e.find("[0, 1]"), std::string::npos) << e;
  // Wrong type.
  e = parse_error("registration:\n  max_iterations: many\n");
  EXPECT_NE(e.find("reg.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("max_iterations"), std::string::npos) << e;
  // Out-of-range integer.
  e = parse_error("registration:\n  silhouette_samples_per_bone: 0\n");
  EXPECT_NE(e.find("registration.silhouette_samples_per_bone"), std::string::npos) << e;
  // A typo is rejected, naming the key.
  e = parse_error("registration:\n  fingertip_sigma: 0.002\n");
  EXPECT_NE(e.find("fingertip_sigma"), std::string::npos) << e;
  // The band's settings.
  e = parse_error("registration:\n  bracelet_depth_ratio: 0.1\n");
  EXPECT_NE(e.find("reg.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("bracelet_depth_ratio"), std::string::npos) << e;
  e = parse_error("registration:\n  bracelet_length_gate: 0\n");
  EXPECT_NE(e.find("bracelet_length_gate"), std::string::npos) << e;
  e = parse_error("registration:\n  bracelet_width_m: 0.2\n");
  EXPECT_NE(e.find("registration.bracelet_width_m"), std::string::npos) << e;
  EXPECT_NE(e.find("[0, 0.1] m"), std::string::npos) << e;
  e = parse_error("registration:\n  bracelet_thickness_sigma: -1\n");
  EXPECT_NE(e.find("bracelet_thickness_sigma"), std::string::npos) << e;
  // The little finger's settings.
  e = parse_error("registration:\n  little_free: sometimes\n");
  EXPECT_NE(e.find("reg.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("little_free"), std::string::npos) << e;
  e = parse_error("registration:\n  little_coupling_sigma_rad: 0\n");
  EXPECT_NE(e.find("registration.little_coupling_sigma_rad"), std::string::npos) << e;
  EXPECT_NE(e.find("[0.0001, 100] rad"), std::string::npos) << e;
  // A σ so small that its weight's square overflows is no measurement (1e-300 m gave IoU 0.16).
  e = parse_error("registration:\n  fingertip_sigma_m: 1e-300\n");
  EXPECT_NE(e.find("reg.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("registration.fingertip_sigma_m: expected a value in [1e-05, 0.1] m, got 1e-300"),
            std::string::npos) << e;
  e = parse_error("registration:\n  joint_ball_sigma_px: 1e-9\n");
  EXPECT_NE(e.find("[0.01, 1000] px"), std::string::npos) << e;
  e = parse_error("registration:\n  prior_sigma_joint_rad: 1e-20\n");
  EXPECT_NE(e.find("registration.prior_sigma_joint_rad"), std::string::npos) << e;
  // A σ whose 0 turns its term off: 0 passes, a tiny one does not.
  EXPECT_EQ(parse_error("registration:\n  bracelet_thickness_sigma: 0\n  digit_axis_sigma_px: 0\n"), "");
  e = parse_error("registration:\n  digit_axis_sigma_px: 1e-200\n");
  EXPECT_NE(e.find("expected 0 (off) or a value in [0.01, 1000] px"), std::string::npos) << e;
  // Not a map.
  e = parse_error("registration: 3\n");
  EXPECT_NE(e.find("registration"), std::string::npos) << e;
}

}  // namespace
}  // namespace spidar::registration
