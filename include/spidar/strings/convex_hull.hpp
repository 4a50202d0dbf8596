#pragma once
/// Whether a point lies inside the convex hull of a few points (a device's fulcrums), for
/// validating a frame centre: a centre outside every string's reach region makes the closed-form
/// position solve and the tension cones meaningless.
#include <span>

#include "spidar/core/types.hpp"

namespace spidar::strings {

/// True if `p` is inside the convex hull of `points` by more than `margin` [m] from every face
/// (`margin` ≥ 0). False for a flat or empty hull (fewer than 4 points not in one plane): it has
/// no inside. O(n⁴) in the number of points: meant for a device's at most 32 fulcrums.
bool inside_convex_hull(std::span<const Vec3> points, const Vec3& p, double margin = 0.0);

}  // namespace spidar::strings
