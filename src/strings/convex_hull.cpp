#include "spidar/strings/convex_hull.hpp"

#include <algorithm>

namespace spidar::strings {

// A face of the hull lies in a plane through three of the points with every point on one side of
// it; `p` is inside when it is on the inner side of every such plane, by more than `margin`.
bool inside_convex_hull(std::span<const Vec3> points, const Vec3& p, double margin) {
  const std::size_t n = points.size();
  if (n < 4) return false;
  // Tolerances scale with the points' extent [m].
  double extent = 0.0;
  for (const Vec3& q : points) extent = std::max(extent, (q - points[0]).norm());
  if (!(extent > 0.0)) return false;
  const double eps = 1e-12 * extent;
  bool any_face = false;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t k = j + 1; k < n; ++k) {
        Vec3 normal = (points[j] - points[i]).cross(points[k] - points[i]);
        const double len = normal.norm();
        if (!(len > eps * extent)) continue;  // (an area)  // collinear triple: no plane
        normal /= len;
        bool below = false, above = false;
        for (const Vec3& q : points) {
          const double d = normal.dot(q - points[i]);
          below = below || d < -eps;
          above = above || d > eps;
        }
        if (below && above) continue;  // points on both sides: not a face
        if (!below && !above) return false;  // every point in this plane: a flat hull
        any_face = true;
        const double outward = below ? 1.0 : -1.0;  // the points lie on the other side
        if (outward * normal.dot(p - points[i]) > -margin) return false;
      }
    }
  }
  return any_face;
}

}  // namespace spidar::strings
