#include "spidar/hand/hand_shape.hpp"

#include <cmath>
#include <string>

#include "spidar/core/units.hpp"

namespace spidar::hand {
namespace {

// A published set of proportions: segment lengths in units of 0.0959 m for a 0.19 m hand.
constexpr double kUnitPerHandLength = 0.0959 / 0.19;

struct FingerProportions {
  std::array<double, 4> length;  // metacarpal, proximal, middle, distal [units]
  double mcp_x;                  // MCP position across the palm [fraction of width]
  std::array<double, 4> radius;  // per segment [fraction of width]
  double abduction_sign;
};

// Index, middle, ring, little. MCP spacing ≈ a quarter of the palm breadth with the middle
// finger on the y axis of H; radii give ≈ 18 mm wide proximal phalanges on a 0.085 m palm.
constexpr std::array<FingerProportions, 4> kFingers = {{
    {{0.66, 0.366, 0.232, 0.202}, -0.25, {0.11, 0.105, 0.095, 0.085}, +1.0},
    {{0.645, 0.404, 0.248, 0.210}, 0.0, {0.11, 0.108, 0.098, 0.088}, 0.0},
    {{0.58, 0.366, 0.226, 0.187}, 0.235, {0.10, 0.100, 0.090, 0.080}, -1.0},
    {{0.52, 0.278, 0.176, 0.158}, 0.45, {0.09, 0.088, 0.080, 0.072}, -1.0},
}};
// The metacarpal bases sit closer together than the MCPs (the metacarpals fan out).
constexpr double kBaseSpreadFraction = 0.7;

// Thumb: metacarpal/proximal/distal (the published set); the rest are our modelling choices: CMC joint
// on the radial, palmar side of the carpus; the metacarpal points 30° from y toward the radial
// side and is pronated 50° about its own axis so the thumb pad faces the fingers.
constexpr std::array<double, 3> kThumbLength = {0.390, 0.311, 0.232};
constexpr std::array<double, 3> kThumbRadius = {0.14, 0.125, 0.115};  // fraction of width
constexpr double kThumbCmcX = -0.26;                                  // fraction of width
constexpr double kThumbCmcY = 0.12;                                   // fraction of length
constexpr double kThumbCmcZ = -0.10;                                  // fraction of width
constexpr double kThumbSpreadDeg = 30.0;                              // about +z_H, toward −x_H
constexpr double kThumbPronationDeg = -50.0;  // about the metacarpal's own y axis

// Palm box: from the carpus to the MCP line, half as thick as ~0.26 of the palm breadth.
constexpr double kPalmHalfThickness = 0.13;  // fraction of width
constexpr double kPalmCentreZ = -0.03;       // fraction of width (the palm bulges palmar)

}  // namespace

Status validate_dimensions(const HandDimensions& d) {
  auto fail = [](const std::string& what) { return Status(Error{"hand dimensions: " + what}); };
  if (!(d.length >= 0.12 && d.length <= 0.26)) {
    return fail("length: expected 0.12..0.26 m, got " + std::to_string(d.length));
  }
  if (!(d.width >= 0.05 && d.width <= 0.13)) {
    return fail("width: expected 0.05..0.13 m, got " + std::to_string(d.width));
  }
  const double ratio = d.width / d.length;
  if (!(ratio >= 0.3 && ratio <= 0.65)) {
    return fail("width: expected width/length in 0.3..0.65, got " + std::to_string(ratio));
  }
  if (!(d.thickness >= 0.6 && d.thickness <= 1.6)) {
    return fail("thickness: expected 0.6..1.6 (× the proportions' digit radii), got " +
                std::to_string(d.thickness));
  }
  if (!d.fingertip_offset.allFinite() || d.fingertip_offset.norm() > 0.02) {
    return fail("fingertip_offset: expected a finite offset of at most 0.02 m");
  }
  return Ok{};
}

Result<HandShape> make_hand_shape(const HandDimensions& dims) {
  if (auto s = validate_dimensions(dims); !s.ok()) return s.error();
  const double L = dims.length;
  const double W = dims.width;
  const double unit = kUnitPerHandLength * L;

  HandShape shape;
  shape.dimensions = dims;

  // Carpal offset: wrist → middle fingertip = L with straight fingers (middle metacarpal on y).
  const auto& mid = kFingers[1].length;
  const double carpal = L - unit * (mid[0] + mid[1] + mid[2] + mid[3]);

  double min_mcp_y = 1e9;
  double x_lo = 1e9;
  double x_hi = -1e9;
  for (int i = 0; i < 4; ++i) {
    const auto& fp = kFingers[i];
    DigitShape& d = shape.digits[kIndex + i];
    const double x_mcp = fp.mcp_x * W;
    const double dx = (1.0 - kBaseSpreadFraction) * x_mcp;
    const double meta = unit * fp.length[0];
    const double dy = std::sqrt(meta * meta - dx * dx);  // meta > |dx| for valid dimensions
    const Vec3 y_dir = Vec3(dx, dy, 0.0) / meta;
    d.p_H_base = Vec3(kBaseSpreadFraction * x_mcp, carpal, 0.0);
    d.R_H_digit.col(1) = y_dir;
    d.R_H_digit.col(2) = Vec3::UnitZ();
    d.R_H_digit.col(0) = y_dir.cross(Vec3::UnitZ());
    for (int k = 0; k < 4; ++k) {
      d.length[k] = unit * fp.length[k];
      d.radius[k] = dims.thickness * W * fp.radius[k];
    }
    d.phalanges = 3;
    d.abduction_sign = fp.abduction_sign;
    d.p_H_mcp = d.p_H_base + meta * y_dir;
    min_mcp_y = std::min(min_mcp_y, d.p_H_mcp.y());
    // The palm's breadth is the width's alone, whatever the digits' thickness.
    x_lo = std::min(x_lo, d.p_H_mcp.x() - W * fp.radius[0]);
    x_hi = std::max(x_hi, d.p_H_mcp.x() + W * fp.radius[0]);
  }

  DigitShape& t = shape.digits[kThumb];
  t.p_H_base = Vec3(kThumbCmcX * W, kThumbCmcY * L, kThumbCmcZ * W);
  t.R_H_digit = (Eigen::AngleAxisd(units::deg_to_rad(kThumbSpreadDeg), Vec3::UnitZ()) *
                 Eigen::AngleAxisd(units::deg_to_rad(kThumbPronationDeg), Vec3::UnitY()))
                    .toRotationMatrix();
  for (int k = 0; k < 3; ++k) {
    t.length[k] = unit * kThumbLength[k];
    t.radius[k] = dims.thickness * W * kThumbRadius[k];
  }
  t.length[3] = 0.0;
  t.radius[3] = 0.0;
  t.phalanges = 2;
  t.abduction_sign = 0.0;
  t.p_H_mcp = t.p_H_base + t.length[0] * t.R_H_digit.col(1);
  shape.thumb_flexion_axis = -Vec3::UnitZ();
  shape.thumb_abduction_axis = Vec3::UnitZ().cross(t.R_H_digit.col(1)).normalized();

  const double y_lo = 0.3 * carpal;
  shape.palm.p_H_centre = Vec3(0.5 * (x_lo + x_hi), 0.5 * (y_lo + min_mcp_y), kPalmCentreZ * W);
  shape.palm.half_extents =
      Vec3(0.5 * (x_hi - x_lo), 0.5 * (min_mcp_y - y_lo), kPalmHalfThickness * W);
  return shape;
}

const HandShape& default_hand_shape() {
  static const HandShape shape = make_hand_shape(HandDimensions{}).value();
  return shape;
}

}  // namespace spidar::hand
