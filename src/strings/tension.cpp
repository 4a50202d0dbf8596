#include "spidar/strings/tension.hpp"

#include "sym3.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <sstream>

namespace spidar::strings {
namespace {

enum class Bound : unsigned char { kFree, kLower, kUpper };

using StringSq = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor,
                               kMaxStrings, kMaxStrings>;

struct ActiveSet {
  std::array<Bound, kMaxStrings> bound{};
  int iterations = 0;
};

/// Primal active-set method for min ½ tᵀ H t − cᵀ t over the box, H = UᵀU + εI (strictly convex).
/// Returns which strings end at a bound; `t` is the regularised optimum.
ActiveSet find_active_set(const StringMat& U, const Vec3& f, double lo, double hi, double eps,
                          StringVec& t) {
  const int n = static_cast<int>(U.cols());
  StringSq H = U.transpose() * U;
  H.diagonal().array() += eps;
  const StringVec c = U.transpose() * f;
  const double tol = 1e-12 * (1.0 + c.cwiseAbs().maxCoeff());

  ActiveSet as;
  t = H.llt().solve(c);
  for (int i = 0; i < n; ++i) {
    as.bound[i] = Bound::kFree;
    if (t[i] <= lo) as.bound[i] = Bound::kLower, t[i] = lo;
    if (t[i] >= hi) as.bound[i] = Bound::kUpper, t[i] = hi;
  }

  std::array<int, kMaxStrings> free_idx{};
  const int max_iterations = 4 * n + 10;
  for (; as.iterations < max_iterations; ++as.iterations) {
    int m = 0;
    for (int i = 0; i < n; ++i)
      if (as.bound[i] == Bound::kFree) free_idx[m++] = i;
    if (m > 0) {
      // Optimum on the current face: H_FF z = c_F − H_FB t_B.
      StringSq Hff(m, m);
      StringVec rhs(m);
      for (int a = 0; a < m; ++a) {
        const int i = free_idx[a];
        double r = c[i];
        for (int j = 0; j < n; ++j)
          if (as.bound[j] != Bound::kFree) r -= H(i, j) * t[j];
        rhs[a] = r;
        for (int b = 0; b < m; ++b) Hff(a, b) = H(i, free_idx[b]);
      }
      const StringVec z = Hff.llt().solve(rhs);
      double alpha = 1.0;
      int blocking = -1;
      Bound blocking_bound = Bound::kFree;
      for (int a = 0; a < m; ++a) {
        const int i = free_idx[a];
        const double step = z[a] - t[i];
        if (z[a] < lo && step < 0.0) {
          const double s = (lo - t[i]) / step;
          if (s < alpha) alpha = s, blocking = i, blocking_bound = Bound::kLower;
        } else if (z[a] > hi && step > 0.0) {
          const double s = (hi - t[i]) / step;
          if (s < alpha) alpha = s, blocking = i, blocking_bound = Bound::kUpper;
        }
      }
      for (int a = 0; a < m; ++a) t[free_idx[a]] += alpha * (z[a] - t[free_idx[a]]);
      if (blocking >= 0) {
        as.bound[blocking] = blocking_bound;
        t[blocking] = blocking_bound == Bound::kLower ? lo : hi;
        continue;
      }
    }
    // Face optimum reached: release the bound with the most negative multiplier, if any.
    const StringVec g = H * t - c;
    int worst = -1;
    double worst_mult = -tol;
    for (int i = 0; i < n; ++i) {
      if (as.bound[i] == Bound::kFree) continue;
      const double mult = as.bound[i] == Bound::kLower ? g[i] : -g[i];
      if (mult < worst_mult) worst_mult = mult, worst = i;
    }
    if (worst < 0) break;
    as.bound[worst] = Bound::kFree;
  }
  return as;
}

/// Exact tensions for a given active set: bounded strings at their bound, free strings the
/// minimum-norm least-squares solution of U_F t_F = f − U_B t_B.
void solve_on_active_set(const StringMat& U, const Vec3& f, double lo, double hi,
                         const ActiveSet& as, StringVec& t) {
  const int n = static_cast<int>(U.cols());
  Vec3 rest = f;
  std::array<int, kMaxStrings> free_idx{};
  int m = 0;
  for (int i = 0; i < n; ++i) {
    if (as.bound[i] == Bound::kFree) {
      free_idx[m++] = i;
    } else {
      t[i] = as.bound[i] == Bound::kLower ? lo : hi;
      rest -= t[i] * U.col(i);
    }
  }
  if (m == 0) return;
  StringMat Uf(3, m);
  for (int a = 0; a < m; ++a) Uf.col(a) = U.col(free_idx[a]);
  StringVec tf(m);
  if (m == 3) {
    const Mat3 Us = Uf;
    Eigen::FullPivLU<Mat3> lu(Us);
    if (lu.isInvertible()) {
      tf = lu.solve(rest);
    } else {
      tf = Uf.completeOrthogonalDecomposition().solve(rest);
    }
  } else if (m < 3) {
    const StringSq N = Uf.transpose() * Uf;
    Eigen::LDLT<StringSq> ldlt(N);
    tf = ldlt.solve(Uf.transpose() * rest);
    if (ldlt.info() != Eigen::Success || !tf.allFinite() || ldlt.rcond() < 1e-12)
      tf = Uf.completeOrthogonalDecomposition().solve(rest);
  } else {
    // Underdetermined: minimum norm t_F = U_Fᵀ (U_F U_Fᵀ)⁻¹ rest.
    const Mat3 N = Uf * Uf.transpose();
    Eigen::LLT<Mat3> llt(N);
    const Vec3 y = llt.solve(rest);
    if (llt.info() == Eigen::Success && y.allFinite() && llt.rcond() > 1e-12) {
      tf = Uf.transpose() * y;
    } else {
      tf = Uf.completeOrthogonalDecomposition().solve(rest);
    }
  }
  for (int a = 0; a < m; ++a) t[free_idx[a]] = tf[a];
}

/// KKT conditions of the exact (unregularised) bounded least squares.
bool satisfies_kkt(const StringMat& U, const Vec3& f, double lo, double hi, const ActiveSet& as,
                   const StringVec& t) {
  const int n = static_cast<int>(U.cols());
  const double tol_t = 1e-10 * (1.0 + hi);
  const Vec3 r = U * t - f;
  const double tol_g = 1e-9 * (1.0 + f.norm() + n * hi);
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(t[i])) return false;
    const double g = U.col(i).dot(r);
    switch (as.bound[i]) {
      case Bound::kFree:
        if (t[i] < lo - tol_t || t[i] > hi + tol_t) return false;
        break;
      case Bound::kLower:
        if (g < -tol_g) return false;
        break;
      case Bound::kUpper:
        if (g > tol_g) return false;
        break;
    }
  }
  return true;
}

/// The least-norm solution of U t = f when U has full row rank. If it lies within the bounds it
/// is the exact optimum (zero residual, least norm), and the active-set search is not needed.
bool solve_unconstrained(const StringMat& U, const Vec3& f, double lo, double hi, StringVec& t) {
  const int n = static_cast<int>(U.cols());
  if (n == 3) {
    const Mat3 U3 = U;
    Mat3 inv;
    double det = 0.0;
    bool invertible = false;
    U3.computeInverseAndDetWithCheck(inv, det, invertible, 1e-9);
    if (!invertible) return false;
    t = inv * f;
  } else if (n > 3) {
    Vec3 y;
    if (!detail::solve_sym3(U * U.transpose(), f, y, 1e-9)) return false;
    t = U.transpose() * y;
  } else {
    return false;
  }
  return t.allFinite() && t.minCoeff() >= lo && t.maxCoeff() <= hi;
}

}  // namespace

Result<StringMat> string_directions(const PointGeometry& g, const Vec3& p_WF) {
  if (!p_WF.allFinite()) return Error{"fingertip position is not finite"};
  StringMat U(3, g.n);
  for (int i = 0; i < g.n; ++i) {
    const Vec3 d = g.p_WA[i] - p_WF;
    const double len = d.norm();
    if (len < 1e-4) {
      return Error{"string " + std::to_string(i) +
                   ": fingertip is at its fulcrum (< 0.1 mm), so the string has no direction"};
    }
    U.col(i) = d / len;
  }
  return U;
}

Result<TensionSolution> solve_tensions(const StringMat& U, const Vec3& f,
                                       const TensionLimits& limits) {
  if (!f.allFinite()) return Error{"desired force is not finite"};
  if (!U.allFinite()) return Error{"string directions are not finite"};
  if (U.cols() < 1) return Error{"no strings"};
  if (!(limits.t_min >= 0.0 && limits.t_min <= limits.t_max && std::isfinite(limits.t_max))) {
    std::ostringstream os;
    os << "tension limits [" << limits.t_min << ", " << limits.t_max
       << "] N; expected 0 <= t_min <= t_max < inf";
    return Error{os.str()};
  }
  const double lo = limits.t_min, hi = limits.t_max;
  TensionSolution sol;
  StringVec t_reg(U.cols());
  sol.t.resize(U.cols());
  int iterations = 0;
  if (solve_unconstrained(U, f, lo, hi, sol.t)) {
    sol.f_displayed = U * sol.t;
    sol.reachable = true;
    return sol;
  }
  // ε only guides the active-set search; the tensions come from the exact solve on that set.
  for (const double eps : {1e-10, 1e-14, 1e-7}) {
    const ActiveSet as = find_active_set(U, f, lo, hi, eps, t_reg);
    iterations += as.iterations + 1;
    solve_on_active_set(U, f, lo, hi, as, sol.t);
    if (satisfies_kkt(U, f, lo, hi, as, sol.t)) break;
    // Keep the regularised optimum if the exact one is no better (degenerate corner).
    if (!sol.t.allFinite()) sol.t = t_reg;
  }
  sol.t = sol.t.cwiseMax(lo).cwiseMin(hi);
  sol.iterations = iterations;
  sol.f_displayed = U * sol.t;
  sol.reachable = (sol.f_displayed - f).norm() <= 1e-9 * (1.0 + f.norm());
  return sol;
}

Result<TensionSolution> solve_tensions(const PointGeometry& g, const Vec3& p_WF, const Vec3& f,
                                       const TensionLimits& limits) {
  auto U = string_directions(g, p_WF);
  if (!U) return U.error();
  return solve_tensions(*U, f, limits);
}

}  // namespace spidar::strings
