// inside_convex_hull against an independent reference: by Carathéodory's theorem a point is in
// the hull of points in 3-D iff it is in a tetrahedron of four of them (brute force over all
// quadruples, with barycentric coordinates).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "spidar/strings/convex_hull.hpp"

namespace spidar::strings {
namespace {

bool in_some_tetrahedron(const std::vector<Vec3>& pts, const Vec3& p) {
  const std::size_t n = pts.size();
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      for (std::size_t c = b + 1; c < n; ++c)
        for (std::size_t d = c + 1; d < n; ++d) {
          Eigen::Matrix3d m;
          m << pts[b] - pts[a], pts[c] - pts[a], pts[d] - pts[a];
          if (std::abs(m.determinant()) < 1e-12) continue;
          const Vec3 w = m.inverse() * (p - pts[a]);
          if (w.minCoeff() >= 0 && w.sum() <= 1) return true;
        }
  return false;
}

TEST(ConvexHull, AgreesWithTetrahedraOverRandomPointsAndQueries) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int inside = 0, outside = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Vec3> pts;
    for (int i = 0; i < 4 + trial % 7; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
    for (int q = 0; q < 25; ++q) {
      const Vec3 p(u(rng), u(rng), u(rng));
      const bool ref = in_some_tetrahedron(pts, p);
      // Points within 1e-6 of a face could go either way in floating point: not used.
      if (ref != inside_convex_hull(pts, p, -1e-6) || ref != inside_convex_hull(pts, p, 1e-6)) {
        EXPECT_EQ(inside_convex_hull(pts, p, -1e-6), inside_convex_hull(pts, p, 1e-6))
            << "trial " << trial << " query " << q << ": answer depends on a 1e-6 margin only";
        continue;
      }
      EXPECT_EQ(inside_convex_hull(pts, p), ref) << "trial " << trial << " query " << q;
      (ref ? inside : outside)++;
    }
  }
  EXPECT_GT(inside, 50);  // both answers were exercised
  EXPECT_GT(outside, 50);
}

TEST(ConvexHull, FlatOrTinySetsHaveNoInsideAndMarginsShrinkTheHull) {
  const std::vector<Vec3> square = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  EXPECT_FALSE(inside_convex_hull(square, Vec3(0.5, 0.5, 0.0)));
  EXPECT_FALSE(inside_convex_hull(std::vector<Vec3>{}, Vec3::Zero()));
  const std::vector<Vec3> cube = {{-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
                                  {-1, -1, 1},  {1, -1, 1},  {-1, 1, 1},  {1, 1, 1}};
  EXPECT_TRUE(inside_convex_hull(cube, Vec3::Zero()));
  EXPECT_TRUE(inside_convex_hull(cube, Vec3(0.9, 0, 0), 0.05));
  EXPECT_FALSE(inside_convex_hull(cube, Vec3(0.9, 0, 0), 0.2));
  EXPECT_FALSE(inside_convex_hull(cube, Vec3(100, 0, 0)));
}

}  // namespace
}  // namespace spidar::strings
