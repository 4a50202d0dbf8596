#include "reference_tension.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace spidar::reference {

TensionReference brute_force_tensions(const Eigen::MatrixXd& U, const Eigen::Vector3d& f,
                                      double lo, double hi) {
  const int n = static_cast<int>(U.cols());
  int patterns = 1;
  for (int i = 0; i < n; ++i) patterns *= 3;
  struct Candidate {
    Eigen::VectorXd t;
    double objective, norm;
  };
  std::vector<Candidate> feasible_sets;
  const double feas_tol = 1e-11 * (1.0 + hi);
  for (int code = 0; code < patterns; ++code) {
    Eigen::VectorXd t(n);
    std::vector<int> free;
    int c = code;
    Eigen::Vector3d rest = f;
    for (int i = 0; i < n; ++i, c /= 3) {
      if (c % 3 == 0) {
        free.push_back(i);
      } else {
        t[i] = c % 3 == 1 ? lo : hi;
        rest -= t[i] * U.col(i);
      }
    }
    if (!free.empty()) {
      Eigen::MatrixXd Uf(3, static_cast<int>(free.size()));
      for (std::size_t a = 0; a < free.size(); ++a) Uf.col(static_cast<int>(a)) = U.col(free[a]);
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(Uf, Eigen::ComputeThinU | Eigen::ComputeThinV);
      svd.setThreshold(1e-13);
      const Eigen::VectorXd tf = svd.solve(rest);
      bool feasible = true;
      for (std::size_t a = 0; a < free.size(); ++a) {
        const double v = tf[static_cast<int>(a)];
        feasible = feasible && v >= lo - feas_tol && v <= hi + feas_tol;
        t[free[a]] = std::min(hi, std::max(lo, v));
      }
      if (!feasible) continue;
    }
    feasible_sets.push_back({t, (U * t - f).squaredNorm(), t.squaredNorm()});
  }
  double min_obj = std::numeric_limits<double>::infinity();
  for (const auto& cand : feasible_sets) min_obj = std::min(min_obj, cand.objective);
  const double tie = 1e-10 * (1.0 + min_obj);
  TensionReference best;
  best.candidates = static_cast<int>(feasible_sets.size());
  double best_norm = std::numeric_limits<double>::infinity();
  for (const auto& cand : feasible_sets) {
    if (cand.objective <= min_obj + tie && cand.norm < best_norm) {
      best.t = cand.t;
      best_norm = cand.norm;
    }
  }
  best.objective = (U * best.t - f).squaredNorm();
  return best;
}

TensionReference projected_gradient_tensions(const Eigen::MatrixXd& U, const Eigen::Vector3d& f,
                                             double lo, double hi, double tol,
                                             int max_iterations) {
  const int n = static_cast<int>(U.cols());
  const Eigen::MatrixXd H = U.transpose() * U;
  const Eigen::VectorXd c = U.transpose() * f;
  const double L = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().maxCoeff();
  Eigen::VectorXd x = Eigen::VectorXd::Constant(n, lo), y = x, x_prev = x;
  double tk = 1.0;
  TensionReference out;
  int it = 0;
  for (; it < max_iterations; ++it) {
    x_prev = x;
    x = (y - (H * y - c) / L).cwiseMax(lo).cwiseMin(hi);
    const double tk1 = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * tk * tk));
    y = x + ((tk - 1.0) / tk1) * (x - x_prev);
    tk = tk1;
    if ((x - x_prev).norm() < tol) break;
  }
  out.t = x;
  out.objective = (U * x - f).squaredNorm();
  out.candidates = it;
  return out;
}

}  // namespace spidar::reference
