#include <gtest/gtest.h>

#include <sstream>

#include <limits>

#include "spidar/strings/position.hpp"
#include "test_support.hpp"

namespace spidar::strings {
namespace {

using testing::random_workspace_point;

std::span<const double> as_span(const StringVec& v) { return {v.data(), static_cast<size_t>(v.size())}; }

void round_trip(const DeviceConfig& cfg, int points_per_finger, double half) {
  std::mt19937_64 rng(42);
  double worst = 0;
  for (const auto& f : cfg.fingers) {
    for (int k = 0; k < points_per_finger; ++k) {
      const Vec3 p = random_workspace_point(f.geometry, rng, half);
      const StringVec l = string_lengths(f.geometry, p);
      auto est = solve_position(f.geometry, as_span(l));
      ASSERT_TRUE(est.ok()) << est.error().message;
      EXPECT_TRUE(est->consistent) << f.name;
      worst = std::max(worst, (est->p_WF - p).norm());
      ASSERT_LT((est->p_WF - p).norm(), 1e-9) << f.name << " at " << p.transpose();
    }
  }
  {
    std::ostringstream os;
    os << std::scientific << worst;
    ::testing::Test::RecordProperty("worst_error_m", os.str());
  }
}

TEST(Position, ClosedFormRoundTripSpidar8) { round_trip(testing::spidar8(), 2000, 0.2); }

TEST(Position, LeastSquaresRoundTripG4) { round_trip(testing::spidar_g4(), 5000, 0.15); }

TEST(Position, ClosedFormMatchesTheCorrectedAlpha3AndPicksTheInnerRoot) {
  // A right-angled layout where the answer is known by hand: A1 = 0, A2 = e_x, A3 = e_y,
  // inner point above the plane; P = (0.3, 0.4, 0.5).
  const std::vector<Vec3> A = {Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()};
  auto g = make_point_geometry(A, Vec3(0.2, 0.2, 1.0)).value();
  const Vec3 p(0.3, 0.4, 0.5);
  const StringVec l = string_lengths(g, p);
  const auto cf = closed_form_position(g.triple, l[0], l[1], l[2]);
  EXPECT_NEAR(cf.discriminant, 0.25, 1e-12);  // α3² sin²θ = z² for orthogonal n1, n2
  EXPECT_TRUE(cf.p_WF.isApprox(p, 1e-12));
  const auto mirror = closed_form_position(g.triple, l[0], l[1], l[2], /*inner=*/false);
  EXPECT_TRUE(mirror.p_WF.isApprox(Vec3(0.3, 0.4, -0.5), 1e-12));
  // With the inner point below the plane the other root is chosen.
  auto g_below = make_point_geometry(A, Vec3(0.2, 0.2, -1.0)).value();
  EXPECT_TRUE(solve_position(g_below, as_span(l))->p_WF.isApprox(Vec3(0.3, 0.4, -0.5), 1e-12));
}

TEST(Position, SkewedTripleUsesSinTheta) {
  // Non-orthogonal n1, n2 (θ = 60°): a misprinted α3 (no 1/sinθ, or + instead of −) fails here.
  const std::vector<Vec3> A = {Vec3::Zero(), Vec3(0.4, 0, 0), Vec3(0.1, 0.1 * std::sqrt(3.0), 0)};
  auto g = make_point_geometry(A, Vec3(0.1, 0.05, 0.3)).value();
  const Vec3 p(0.12, 0.07, 0.21);
  const StringVec l = string_lengths(g, p);
  EXPECT_TRUE(solve_position(g, as_span(l))->p_WF.isApprox(p, 1e-12));
}

/// Σ (‖P − A_i‖ − l_i)² for the independent check below.
double cost(const PointGeometry& g, const Vec3& p, const StringVec& l) {
  double c = 0;
  for (int i = 0; i < g.n; ++i) c += std::pow((p - g.p_WA[i]).norm() - l[i], 2);
  return c;
}

/// Brute-force local check: no point on a fine shell of random directions around the estimate,
/// at several radii, has a lower least-squares cost.
void expect_local_minimum(const PointGeometry& g, const Vec3& p, const StringVec& l,
                          std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  const double c0 = cost(g, p, l);
  for (double r : {1e-5, 1e-4, 1e-3, 1e-2, 3e-2}) {
    for (int k = 0; k < 300; ++k) {
      const Vec3 d = Vec3(n(rng), n(rng), n(rng)).normalized() * r;
      ASSERT_GE(cost(g, p + d, l), c0 - 1e-15) << "r=" << r;
    }
  }
}

TEST(Position, InconsistentLengthsGiveFlaggedLeastSquaresEstimate) {
  const auto& f = testing::spidar8().fingers[1];
  std::mt19937_64 rng(7);
  // Triangle inequality broken: two strings far too short for their fulcrums' distance.
  StringVec l(3);
  l << 0.05, 0.05, 0.6;
  auto est = solve_position(f.geometry, as_span(l));
  ASSERT_TRUE(est.ok());
  EXPECT_FALSE(est->consistent);
  EXPECT_TRUE(est->p_WF.allFinite());
  EXPECT_GT(est->residual, 1e-3);
  EXPECT_NEAR(est->residual, length_residual_rms(f.geometry, est->p_WF, as_span(l)), 1e-15);
  expect_local_minimum(f.geometry, est->p_WF, l, rng);

  // Strings slightly too short everywhere: negative discriminant.
  const Vec3 p = random_workspace_point(f.geometry, rng, 0.1);
  const StringVec l_true = string_lengths(f.geometry, p);
  StringVec l2 = l_true;
  double disc = 1.0;
  for (double s = 0.95; s > 0.05 && disc >= 0.0; s -= 0.05) {
    l2 = s * l_true;
    const auto& tr = f.geometry.triple;
    disc = closed_form_position(tr, l2[tr.index[0]], l2[tr.index[1]], l2[tr.index[2]]).discriminant;
  }
  ASSERT_LT(disc, 0.0);
  auto est2 = solve_position(f.geometry, as_span(l2));
  ASSERT_TRUE(est2.ok());
  EXPECT_FALSE(est2->consistent);
  EXPECT_TRUE(est2->p_WF.allFinite());
  expect_local_minimum(f.geometry, est2->p_WF, l2, rng);
}

TEST(Position, NoisyOverdeterminedLengthsReachTheLeastSquaresOptimum) {
  const auto& g = testing::spidar_g4().fingers[0].geometry;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0, 2e-4);
  for (int k = 0; k < 200; ++k) {
    const Vec3 p = random_workspace_point(g, rng, 0.12);
    StringVec l = string_lengths(g, p);
    for (int i = 0; i < g.n; ++i) l[i] += noise(rng);
    auto est = solve_position(g, as_span(l));
    ASSERT_TRUE(est.ok());
    EXPECT_TRUE(est->consistent);
    EXPECT_LT((est->p_WF - p).norm(), 3e-3);
    // Distance to the stationary point by one full Newton step (exact Hessian, not the solver's
    // Gauss-Newton one): the estimate is within 1 nm of the least-squares optimum.
    Vec3 grad = Vec3::Zero();
    Mat3 hess = Mat3::Zero();
    for (int i = 0; i < g.n; ++i) {
      const Vec3 d = est->p_WF - g.p_WA[i];
      const double dist = d.norm(), r = dist - l[i];
      const Vec3 j = d / dist;
      grad += r * j;
      hess += j * j.transpose() + (r / dist) * (Mat3::Identity() - j * j.transpose());
    }
    EXPECT_LT(hess.fullPivLu().solve(grad).norm(), 1e-9);
    if (k < 20) expect_local_minimum(g, est->p_WF, l, rng);
  }
}

TEST(Position, OverdeterminedPicksTheMirrorRootTheExtraStringsAgreeWith) {
  // Four coplanar fulcrums in z = 0 would be ambiguous; here the fourth is off the plane of the
  // best triple, so the far side of that plane is resolvable.
  const auto& g = testing::spidar_g4().fingers[0].geometry;
  const Vec3 p_outer = g.triple.p_WA1 - 0.02 * g.triple.n3_inner +
                       0.05 * (g.p_W_inner - g.triple.p_WA1).normalized().cross(g.triple.n3_inner);
  const StringVec l = string_lengths(g, p_outer);
  auto est = solve_position(g, as_span(l));
  ASSERT_TRUE(est.ok());
  EXPECT_LT((est->p_WF - p_outer).norm(), 1e-9);
}

TEST(Position, BadLengthsAreErrorsNamingTheString) {
  const auto& g = testing::spidar8().fingers[0].geometry;
  StringVec l(3);
  l << 0.3, std::numeric_limits<double>::quiet_NaN(), 0.3;
  auto r = solve_position(g, as_span(l));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("string 1"), std::string::npos) << r.error().message;
  l << 0.3, 0.3, -0.01;
  r = solve_position(g, as_span(l));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("string 2"), std::string::npos);
  l << std::numeric_limits<double>::infinity(), 0.3, 0.3;
  EXPECT_FALSE(solve_position(g, as_span(l)).ok());
  const std::vector<double> two = {0.3, 0.3};
  r = solve_position(g, two);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "expected 3 string lengths, got 2");
}

TEST(Position, ZeroLengthsAreFiniteAndFlagged) {
  const auto& g = testing::spidar8().fingers[5].geometry;
  const std::vector<double> zero = {0.0, 0.0, 0.0};
  auto est = solve_position(g, zero);
  ASSERT_TRUE(est.ok());
  EXPECT_TRUE(est->p_WF.allFinite());
  EXPECT_FALSE(est->consistent);
}

TEST(PointGeometry, RejectsDegenerateLayouts) {
  auto msg = [](std::vector<Vec3> A) {
    auto r = make_point_geometry(A, Vec3(0, 0, 1));
    return r.ok() ? std::string("ok") : r.error().message;
  };
  EXPECT_EQ(msg({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}), "ok");
  EXPECT_NE(msg({Vec3(0, 0, 0), Vec3(0, 0, 0.0005), Vec3(0, 1, 0)}).find("fulcrums 0 and 1 coincide"),
            std::string::npos);
  EXPECT_NE(msg({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)}).find("collinear"), std::string::npos);
  EXPECT_NE(msg({Vec3(0, 0, 0), Vec3(1, 0, 0)}).find("expected 3 to 8 fulcrums, got 2"),
            std::string::npos);
  // Inner point in the fulcrum plane: the root cannot be chosen.
  auto r = make_point_geometry(std::vector<Vec3>{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)},
                               Vec3(0.3, 0.3, 0));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("frame centre lies in the plane"), std::string::npos);
}

}  // namespace
}  // namespace spidar::strings
