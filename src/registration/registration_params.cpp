#include "spidar/registration/registration_params.hpp"

#include <cmath>
#include <sstream>
#include <string>

namespace spidar::registration {
namespace {

// One table of every numeric field with its range, shared by validate() and the parser so that
// both say the same thing and the parser can point at the offending key's line.
struct Field {
  const char* key;
  double RegistrationParams::*real = nullptr;  // exactly one of real / integer is set
  int RegistrationParams::*integer = nullptr;
  double lo;
  double hi;
  bool lo_open;  // (lo, hi] instead of [lo, hi]
  const char* unit;
  bool zero_off = false;  // 0 (the term off) is allowed as well
};

// A σ divides a residual: below these a weight's square overflows the normal equations or
// swamps every other term (fingertip_sigma_m 1e-300 gave IoU 0.16 and 56 mm), so they are the
// smallest σ that still means a measurement.
constexpr double kMinSigmaM = 1e-5;     // 10 µm
constexpr double kMinSigmaPx = 0.01;    // a hundredth of a pixel
constexpr double kMinSigmaRad = 1e-4;   // 0.006°
constexpr double kMinSigmaRatio = 1e-3; // a relative σ

constexpr Field kFields[] = {
    {"fingertip_sigma_m", &RegistrationParams::fingertip_sigma_m, nullptr, kMinSigmaM, 0.1, false, "m"},
    {"wrist_sigma_px", &RegistrationParams::wrist_sigma_px, nullptr, kMinSigmaPx, 1000.0, false, "px"},
    {"bracelet_offset_m", &RegistrationParams::bracelet_offset_m, nullptr, -0.05, 0.05, false, "m"},
    {"bracelet_surface_shift", &RegistrationParams::bracelet_surface_shift, nullptr, 0.0, 1.0, false, ""},
    {"bracelet_radius_per_width", &RegistrationParams::bracelet_radius_per_width, nullptr, 0.0, 1.0, false, ""},
    {"bracelet_standoff_m", &RegistrationParams::bracelet_standoff_m, nullptr, 0.0, 0.02, false, "m"},
    {"bracelet_depth_ratio", &RegistrationParams::bracelet_depth_ratio, nullptr, 0.2, 1.0, false, ""},
    {"bracelet_length_sigma", &RegistrationParams::bracelet_length_sigma, nullptr, kMinSigmaRatio, 1.0, false, "", true},
    {"bracelet_length_min_fill", &RegistrationParams::bracelet_length_min_fill, nullptr, 0.0, 1.0, false, ""},
    {"bracelet_length_tolerance", &RegistrationParams::bracelet_length_tolerance, nullptr, 0.0, 1.0, false, ""},
    {"bracelet_length_gate", &RegistrationParams::bracelet_length_gate, nullptr, 0.0, 10.0, true, ""},
    {"bracelet_width_m", &RegistrationParams::bracelet_width_m, nullptr, 0.0, 0.1, false, "m"},
    {"bracelet_thickness_sigma", &RegistrationParams::bracelet_thickness_sigma, nullptr, kMinSigmaRatio, 1.0, false, "", true},
    {"bracelet_thickness_tolerance", &RegistrationParams::bracelet_thickness_tolerance, nullptr, 0.0, 1.0, false, ""},
    {"joint_ball_sigma_px", &RegistrationParams::joint_ball_sigma_px, nullptr, kMinSigmaPx, 1000.0, false,
     "px"},
    {"joint_ball_alpha", &RegistrationParams::joint_ball_alpha, nullptr, 0.0, 1.0, false, ""},
    {"ball_radius_scale", &RegistrationParams::ball_radius_scale, nullptr, 0.0, 5.0, true, ""},
    {"matte_threshold", &RegistrationParams::matte_threshold, nullptr, 0.0, 1.0, true, ""},
    {"silhouette_sigma_px", &RegistrationParams::silhouette_sigma_px, nullptr, kMinSigmaPx, 1000.0, false,
     "px"},
    {"silhouette_samples_per_bone", nullptr, &RegistrationParams::silhouette_samples_per_bone, 1.0,
     kMaxSilhouetteSamplesPerBone, false, ""},
    {"coverage_sigma_px", &RegistrationParams::coverage_sigma_px, nullptr, kMinSigmaPx, 1000.0, false, "px"},
    {"coverage_stride_px", nullptr, &RegistrationParams::coverage_stride_px, 1.0, 64.0, false, "px"},
    {"coverage_max_px", &RegistrationParams::coverage_max_px, nullptr, 0.0, 1000.0, true, "px"},
    {"coverage_huber_px", &RegistrationParams::coverage_huber_px, nullptr, 0.0, 1000.0, true, "px"},
    {"digit_axis_sigma_px", &RegistrationParams::digit_axis_sigma_px, nullptr, kMinSigmaPx, 1000.0, false, "px", true},
    {"little_coupling_sigma_rad", &RegistrationParams::little_coupling_sigma_rad, nullptr, kMinSigmaRad, 100.0, false,
     "rad"},
    {"forearm_max_bend_rad", &RegistrationParams::forearm_max_bend_rad, nullptr, 0.0, 1.5707963267948966, true, "rad"},
    {"forearm_thickness_sigma", &RegistrationParams::forearm_thickness_sigma, nullptr, kMinSigmaRatio, 100.0, false, ""},
    {"forearm_axis_sigma_rad", &RegistrationParams::forearm_axis_sigma_rad, nullptr, kMinSigmaRad, 100.0, false, "rad"},
    {"forearm_bend_sigma_rad", &RegistrationParams::forearm_bend_sigma_rad, nullptr, kMinSigmaRad, 100.0, false, "rad"},
    {"forearm_bulge_sigma", &RegistrationParams::forearm_bulge_sigma, nullptr, kMinSigmaRatio, 100.0, false, ""},
    {"forearm_previous_sigma_rad", &RegistrationParams::forearm_previous_sigma_rad, nullptr, kMinSigmaRad, 100.0, false,
     "rad"},
    {"prior_sigma_wrist_m", &RegistrationParams::prior_sigma_wrist_m, nullptr, kMinSigmaM, 100.0, false,
     "m"},
    {"prior_sigma_rotation_rad", &RegistrationParams::prior_sigma_rotation_rad, nullptr, kMinSigmaRad,
     100.0, false, "rad"},
    {"prior_sigma_joint_rad", &RegistrationParams::prior_sigma_joint_rad, nullptr, kMinSigmaRad, 100.0,
     false, "rad"},
    {"lambda_initial", &RegistrationParams::lambda_initial, nullptr, 0.0, 1e6, false, ""},
    {"max_iterations", nullptr, &RegistrationParams::max_iterations, 1.0, 1000.0, false, ""},
    {"cost_epsilon", &RegistrationParams::cost_epsilon, nullptr, 0.0, 1e6, false, ""},
    {"step_epsilon", &RegistrationParams::step_epsilon, nullptr, 0.0, 1.0, false, ""},
    {"relative_epsilon", &RegistrationParams::relative_epsilon, nullptr, 0.0, 1.0, false, ""},
};

double value_of(const RegistrationParams& p, const Field& f) {
  return f.real ? p.*f.real : static_cast<double>(p.*f.integer);
}

bool in_range(const Field& f, double v) {
  if (!std::isfinite(v)) return false;
  if (f.zero_off && v == 0.0) return true;
  return (f.lo_open ? v > f.lo : v >= f.lo) && v <= f.hi;
}

// "expected a value in (0, 0.1] m, got -1"
std::string expectation(const Field& f, double v) {
  std::ostringstream os;
  os << "expected " << (f.zero_off ? "0 (off) or " : "") << (f.integer ? "an integer" : "a value") << " in "
     << (f.lo_open ? '(' : '[')
     << f.lo << ", " << f.hi << ']';
  if (*f.unit) os << ' ' << f.unit;
  os << ", got " << v;
  return os.str();
}

}  // namespace

Status validate(const RegistrationParams& p) {
  for (const Field& f : kFields) {
    const double v = value_of(p, f);
    if (!in_range(f, v)) {
      return Error{std::string("registration: ") + f.key + ": " + expectation(f, v)};
    }
  }
  return Ok{};
}

RegistrationParams parse_registration_params(const core::ConfigNode& node) {
  if (!node.is_map()) node.fail("expected a map of registration settings");
  node.expect_keys({"fingertip_sigma_m", "wrist_sigma_px", "bracelet_offset_m",
                    "bracelet_surface_shift", "bracelet_detector_midpoint", "bracelet_radius_per_width", "bracelet_standoff_m",
                    "bracelet_depth_ratio", "bracelet_length_sigma", "bracelet_length_min_fill",
                    "bracelet_length_gate", "bracelet_length_tolerance", "bracelet_width_m",
                    "bracelet_thickness_sigma", "bracelet_thickness_tolerance",
                    "joint_ball_sigma_px", "joint_ball_alpha", "ball_radius_scale",
                    "matte_threshold", "silhouette_term", "silhouette_inward", "silhouette_sigma_px",
                    "silhouette_samples_per_bone", "coverage_sigma_px", "coverage_stride_px",
                    "coverage_max_px", "coverage_huber_px", "digit_axis_sigma_px", "little_free",
                    "little_coupling_sigma_rad", "forearm_from_band", "forearm_max_bend_rad",
                    "forearm_thickness_sigma", "forearm_axis_sigma_rad", "forearm_bend_sigma_rad",
                    "forearm_previous_sigma_rad", "forearm_bulge_sigma", "prior_sigma_wrist_m",
                    "prior_sigma_rotation_rad", "prior_sigma_joint_rad", "lambda_initial",
                    "max_iterations", "cost_epsilon", "step_epsilon", "relative_epsilon"});
  RegistrationParams p;
  for (const Field& f : kFields) {
    const auto child = node.find(f.key);
    if (!child) continue;
    double v = 0;
    if (f.real) {
      v = child->as_double();
      p.*f.real = v;
    } else {
      const std::int64_t i = child->as_int();
      v = static_cast<double>(i);
      if (in_range(f, v)) p.*f.integer = static_cast<int>(i);
    }
    if (!in_range(f, v)) child->fail(expectation(f, v));
  }
  if (auto b = node.find("silhouette_term")) p.silhouette_term = b->as_bool();
  if (auto b = node.find("silhouette_inward")) p.silhouette_inward = b->as_bool();
  if (auto b = node.find("little_free")) p.little_free = b->as_bool();
  if (auto b = node.find("forearm_from_band")) p.forearm_from_band = b->as_bool();
  if (auto b = node.find("bracelet_detector_midpoint")) p.bracelet_detector_midpoint = b->as_bool();
  // Every field was range-checked at its key; this only guards against the table and the
  // struct drifting apart.
  if (auto s = validate(p); !s.ok()) node.fail(s.error().message);
  return p;
}

}  // namespace spidar::registration
