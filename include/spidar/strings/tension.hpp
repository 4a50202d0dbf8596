#pragma once
/// Tension distribution: tensions t ∈ [t_min, t_max]^N whose force Σ t_i u_i is nearest the
/// desired force f (paper eqs 13–14 and the force-cone projection, in its general form):
///
///   t* = argmin ‖U t − f‖²  s.t. t_min ≤ t ≤ t_max,   u_i = (A_i − P)/‖A_i − P‖,
///
/// and, when several t give the same optimal force (N > 3), the one of least ‖t‖.
///
/// Method: a primal active-set method on the slightly regularised problem (+ε‖t‖²) identifies
/// which strings sit at t_min, at t_max or in between; the free tensions are then recomputed
/// exactly (least squares, minimum norm) for that set, and the KKT conditions of the exact problem
/// are checked. If they fail, ε shrinks and the search repeats. The result is the exact optimum
/// to rounding, not a few iterations of an approximate method.
#include "spidar/core/result.hpp"
#include "spidar/strings/point_geometry.hpp"

namespace spidar::strings {

struct TensionSolution {
  StringVec t;              ///< tension of each string [N]
  Vec3 f_displayed = Vec3::Zero();  ///< Σ t_i u_i [N], world
  bool reachable = false;   ///< ‖f_displayed − f_desired‖ ≤ 1e-9 (1 + ‖f_desired‖)
  int iterations = 0;       ///< active-set iterations
};

/// Unit string directions u_i = (A_i − P)/‖A_i − P‖ as the columns of U. Fails if P is within
/// 0.1 mm of a fulcrum or not finite.
Result<StringMat> string_directions(const PointGeometry& geometry, const Vec3& p_WF);

/// Solves for tensions given string directions U (3×N, unit columns) and desired force f [N].
Result<TensionSolution> solve_tensions(const StringMat& U, const Vec3& f_desired,
                                       const TensionLimits& limits);

/// Convenience: directions from the fingertip position, then solve.
Result<TensionSolution> solve_tensions(const PointGeometry& geometry, const Vec3& p_WF,
                                       const Vec3& f_desired, const TensionLimits& limits);

}  // namespace spidar::strings
