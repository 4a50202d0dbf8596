#include <gtest/gtest.h>

#include <sstream>

#include "reference_tension.hpp"
#include "spidar/strings/tension.hpp"
#include "test_support.hpp"

namespace spidar::strings {
namespace {

using testing::random_workspace_point;

Vec3 random_force(std::mt19937_64& rng, double scale) {
  std::normal_distribution<double> n(0, 1);
  return scale * Vec3(n(rng), n(rng), n(rng));
}

/// Compares the fast solver with brute-force enumeration on random problems from `cfg`.
void compare_with_brute_force(const DeviceConfig& cfg, int problems_per_finger,
                              std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> scale(0.0, 25.0);
  const TensionLimits lim = cfg.effective_limits();
  int reachable = 0, total = 0;
  double worst_rel = 0;
  for (const auto& f : cfg.fingers) {
    for (int k = 0; k < problems_per_finger; ++k) {
      const Vec3 p = random_workspace_point(f.geometry, rng, 0.15);
      const StringMat U = string_directions(f.geometry, p).value();
      // Half the problems inside the force cone (positive string combinations), half anywhere.
      Vec3 force = random_force(rng, scale(rng));
      if (k % 2 == 0) {
        std::uniform_real_distribution<double> w(0.4, 15.0);
        force = Vec3::Zero();
        for (int i = 0; i < U.cols(); ++i) force += w(rng) * U.col(i);
      }
      const auto sol = solve_tensions(U, force, lim);
      ASSERT_TRUE(sol.ok()) << sol.error().message;
      const auto ref = reference::brute_force_tensions(Eigen::MatrixXd(U), force, lim.t_min, lim.t_max);
      ASSERT_EQ(ref.t.size(), sol->t.size());
      const double obj = (U * sol->t - force).squaredNorm();
      // Exact: the objective and (the unique least-norm) tensions within 1e-9 relative.
      EXPECT_LE(obj, ref.objective + 1e-9 * (1.0 + ref.objective)) << f.name << " k=" << k;
      const double rel = (sol->t - ref.t).norm() / ref.t.norm();
      worst_rel = std::max(worst_rel, rel);
      EXPECT_LE(rel, 1e-9) << f.name << " k=" << k << "\nfast " << sol->t.transpose()
                           << "\nref  " << ref.t.transpose() << "\nforce " << force.transpose();
      // Bounds and the reported force.
      EXPECT_GE(sol->t.minCoeff(), lim.t_min);
      EXPECT_LE(sol->t.maxCoeff(), lim.t_max);
      EXPECT_TRUE(sol->f_displayed.isApprox(U * sol->t, 1e-14));
      EXPECT_EQ(sol->reachable, ref.objective <= 1e-16 * (1 + force.squaredNorm()))
          << "objective " << ref.objective;
      reachable += sol->reachable;
      ++total;
    }
  }
  // The random problems must exercise both reachable and unreachable forces.
  EXPECT_GT(reachable, total / 20);
  EXPECT_LT(reachable, total - total / 20);
  {
    std::ostringstream os;
    os << std::scientific << worst_rel;
    ::testing::Test::RecordProperty("worst_relative_difference", os.str());
  }
}

TEST(Tension, ThreeStringsMatchActiveSetEnumeration) {
  compare_with_brute_force(testing::spidar8(), 500, 11);
}

TEST(Tension, FourStringsMatchEnumerationIncludingLeastNorm) {
  compare_with_brute_force(testing::spidar_g4(), 3000, 12);
}

TEST(Tension, SixAndEightStringLayoutsMatchEnumeration) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int n : {5, 6, 8}) {
    for (int trial = 0; trial < (n == 8 ? 15 : 60); ++trial) {
      std::vector<Vec3> A;
      for (int i = 0; i < n; ++i) A.emplace_back(u(rng), u(rng), u(rng));
      auto g = make_point_geometry(A, Vec3::Zero());
      if (!g.ok()) continue;
      const Vec3 p = 0.2 * Vec3(u(rng), u(rng), u(rng));
      const StringMat U = string_directions(*g, p).value();
      const Vec3 force = random_force(rng, 10.0);
      const auto sol = solve_tensions(U, force, {0.5, 12.0}).value();
      const auto ref = reference::brute_force_tensions(Eigen::MatrixXd(U), force, 0.5, 12.0);
      EXPECT_LE((U * sol.t - force).squaredNorm(), ref.objective + 1e-9 * (1 + ref.objective));
      EXPECT_LE((sol.t - ref.t).norm(), 1e-9 * ref.t.norm()) << "n=" << n << " trial " << trial;
    }
  }
}

TEST(Tension, ProjectedGradientAgreesOnTheDisplayedForce) {
  // A second, iterative reference: the displayed force is unique even when tensions are not.
  const auto& cfg = testing::spidar_g4();
  std::mt19937_64 rng(9);
  for (int k = 0; k < 100; ++k) {
    const auto& g = cfg.fingers[0].geometry;
    const Vec3 p = random_workspace_point(g, rng, 0.12);
    const Vec3 force = random_force(rng, 8.0);
    const StringMat U = string_directions(g, p).value();
    const auto sol = solve_tensions(U, force, cfg.effective_limits()).value();
    const auto pg = reference::projected_gradient_tensions(Eigen::MatrixXd(U), force, 0.35,
                                                           cfg.effective_limits().t_max, 1e-13);
    EXPECT_LT((sol.f_displayed - U * pg.t).norm(), 1e-6) << k;
    EXPECT_LE((U * sol.t - force).squaredNorm(), pg.objective + 1e-12);
  }
}

TEST(Tension, ReachableForceIsDisplayedExactly) {
  const auto& g = testing::spidar_g4().fingers[0].geometry;
  const StringMat U = string_directions(g, Vec3(0.01, -0.02, 0.03)).value();
  const Vec3 force(1.0, -2.0, 0.5);
  const auto sol = solve_tensions(U, force, {0.35, 17.0}).value();
  EXPECT_TRUE(sol.reachable);
  EXPECT_LT((sol.f_displayed - force).norm(), 1e-12);
}

TEST(Tension, ThreeStringsCannotPushAwayFromTheirFulcrums) {
  const auto& g = testing::spidar8().fingers[0].geometry;  // left thumb: front-bottom unit
  const Vec3 p = Vec3::Zero();
  const StringMat U = string_directions(g, p).value();
  const Vec3 pull_to_fulcrums = (U.col(0) + U.col(1) + U.col(2)).normalized();
  const auto inside = solve_tensions(U, 3.0 * pull_to_fulcrums, {0.35, 17.0}).value();
  EXPECT_TRUE(inside.reachable);
  const auto outside = solve_tensions(U, -3.0 * pull_to_fulcrums, {0.35, 17.0}).value();
  EXPECT_FALSE(outside.reachable);
  EXPECT_TRUE(outside.t.isApprox(StringVec::Constant(3, 0.35)));  // all at t_min
}

TEST(Tension, BadInputsAreErrors) {
  const auto& g = testing::spidar8().fingers[0].geometry;
  auto r = solve_tensions(g, g.p_WA[2], Vec3(1, 0, 0), {0.35, 17.0});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("string 2"), std::string::npos) << r.error().message;
  EXPECT_FALSE(solve_tensions(g, Vec3::Zero(), Vec3(NAN, 0, 0), {0.35, 17.0}).ok());
  EXPECT_FALSE(solve_tensions(g, Vec3(INFINITY, 0, 0), Vec3(1, 0, 0), {0.35, 17.0}).ok());
  r = solve_tensions(g, Vec3::Zero(), Vec3(1, 0, 0), {5.0, 1.0});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("t_min <= t_max"), std::string::npos);
}

TEST(Tension, EqualBoundsPinEveryString) {
  const auto& g = testing::spidar_g4().fingers[0].geometry;
  const auto sol = solve_tensions(g, Vec3::Zero(), Vec3(3, 1, 2), {2.0, 2.0}).value();
  EXPECT_TRUE(sol.t.isApprox(StringVec::Constant(4, 2.0)));
}

}  // namespace
}  // namespace spidar::strings
