#include "spidar/strings/point_geometry.hpp"

#include <cmath>
#include <sstream>

namespace spidar::strings {
namespace {

constexpr double kMinFulcrumDistance = 1e-3;  // [m]
constexpr double kMinTriangleArea = 1e-6;     // [m²], e.g. 1 mm × 2 m
constexpr double kMinInnerDistance = 1e-3;    // [m]

double triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

ClosedFormTriple make_triple(const Vec3& a1, const Vec3& a2, const Vec3& a3, int i1, int i2,
                             int i3, const Vec3& p_W_inner) {
  ClosedFormTriple t;
  t.index = {i1, i2, i3};
  t.p_WA1 = a1;
  t.d1 = (a2 - a1).norm();
  t.d2 = (a3 - a1).norm();
  t.n1 = (a2 - a1) / t.d1;
  t.n2 = (a3 - a1) / t.d2;
  t.cos_theta = t.n1.dot(t.n2);
  const double sin2 = 1.0 - t.cos_theta * t.cos_theta;
  t.inv_sin2_theta = 1.0 / sin2;
  Vec3 n3 = t.n1.cross(t.n2).normalized();
  if (n3.dot(p_W_inner - a1) < 0.0) n3 = -n3;
  t.n3_inner = n3;
  return t;
}

}  // namespace

Status validate_fulcrums(std::span<const Vec3> p_WA) {
  const auto n = static_cast<int>(p_WA.size());
  if (n < 3 || n > kMaxStrings) {
    return Error{"expected 3 to " + std::to_string(kMaxStrings) + " fulcrums, got " +
                 std::to_string(n)};
  }
  for (int i = 0; i < n; ++i) {
    if (!p_WA[i].allFinite()) {
      return Error{"fulcrum " + std::to_string(i) + " is not finite"};
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double d = (p_WA[i] - p_WA[j]).norm();
      if (d < kMinFulcrumDistance) {
        std::ostringstream os;
        os << "fulcrums " << i << " and " << j << " coincide (" << d * 1e3
           << " mm apart); expected distinct points at least 1 mm apart";
        return Error{os.str()};
      }
    }
  }
  double best = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k) best = std::max(best, triangle_area(p_WA[i], p_WA[j], p_WA[k]));
  if (best < kMinTriangleArea) {
    std::ostringstream os;
    os << "fulcrums are collinear (largest triangle area " << best
       << " m²); expected at least three fulcrums spanning a plane";
    return Error{os.str()};
  }
  return Ok{};
}

Result<PointGeometry> make_point_geometry(std::span<const Vec3> p_WA, const Vec3& p_W_inner) {
  if (auto st = validate_fulcrums(p_WA); !st) return st.error();
  if (!p_W_inner.allFinite()) return Error{"inner point (frame centre) is not finite"};
  PointGeometry g;
  g.n = static_cast<int>(p_WA.size());
  g.p_W_inner = p_W_inner;
  for (int i = 0; i < g.n; ++i) g.p_WA[i] = p_WA[i];

  // The best-conditioned triple: largest triangle whose plane keeps the inner point off it.
  double best = -1.0;
  for (int i = 0; i < g.n; ++i) {
    for (int j = i + 1; j < g.n; ++j) {
      for (int k = j + 1; k < g.n; ++k) {
        const double area = triangle_area(p_WA[i], p_WA[j], p_WA[k]);
        if (area < kMinTriangleArea) continue;
        const Vec3 normal = (p_WA[j] - p_WA[i]).cross(p_WA[k] - p_WA[i]).normalized();
        const double inner = std::abs(normal.dot(p_W_inner - p_WA[i]));
        if (inner < kMinInnerDistance) continue;
        if (area > best) {
          best = area;
          g.triple = make_triple(p_WA[i], p_WA[j], p_WA[k], i, j, k, p_W_inner);
        }
      }
    }
  }
  if (best < 0.0) {
    return Error{
        "the frame centre lies in the plane of the fulcrums, so the inner-side root is "
        "ambiguous; expected the centre at least 1 mm off the fulcrum plane"};
  }
  return g;
}

}  // namespace spidar::strings
