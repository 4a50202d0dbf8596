#pragma once
/// The fulcrums of one fingertip's strings, validated and with the constants of the paper's
/// closed-form position (eqs 1–12) precomputed.
#include <array>
#include <span>

#include "spidar/core/result.hpp"
#include "spidar/strings/string_set.hpp"

namespace spidar::strings {

/// Checks that fulcrums can locate a point: 3..kMaxStrings finite points, no two within 1 mm,
/// and at least one triple spanning a plane (not collinear). The error says which fulcrums.
Status validate_fulcrums(std::span<const Vec3> p_WA);

/// Closed-form constants for a triple of fulcrums A1, A2, A3 (paper notation).
struct ClosedFormTriple {
  std::array<int, 3> index{0, 1, 2};  ///< which strings are A1, A2, A3
  Vec3 p_WA1 = Vec3::Zero();          ///< A1 [m], world
  Vec3 n1 = Vec3::UnitX();            ///< (A2 − A1)/d1
  Vec3 n2 = Vec3::UnitY();            ///< (A3 − A1)/d2
  Vec3 n3_inner = Vec3::UnitZ();      ///< unit normal n1×n2/sinθ, signed toward the inner point
  double d1 = 1, d2 = 1;              ///< |A2 − A1|, |A3 − A1| [m]
  double cos_theta = 0;               ///< n1·n2
  double inv_sin2_theta = 1;          ///< 1/sin²θ
};

/// Geometry of one point's strings in the world frame.
struct PointGeometry {
  int n = 0;                                ///< number of strings, 3..kMaxStrings
  std::array<Vec3, kMaxStrings> p_WA = zeros<Vec3, kMaxStrings>();  ///< fulcrum of string i [m], world
  Vec3 p_W_inner = Vec3::Zero();            ///< a point on the frame's inner side (its centre)
  ClosedFormTriple triple;                  ///< best-conditioned triple for the closed form
};

/// Builds the geometry. `p_W_inner` picks the closed form's root: the fingertip is on the side of
/// the fulcrum plane where this point (the frame centre) is. Fails if the fulcrums are degenerate
/// or the inner point lies in the chosen fulcrum plane.
Result<PointGeometry> make_point_geometry(std::span<const Vec3> p_WA, const Vec3& p_W_inner);

}  // namespace spidar::strings
