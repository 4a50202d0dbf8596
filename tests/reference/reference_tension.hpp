#pragma once
/// Independent reference solvers for the tension problem
///   min ‖U t − f‖²  s.t. lo ≤ t ≤ hi,  then least ‖t‖ among the optima,
/// used to check and to time `strings::solve_tensions`. Deliberately different methods:
/// enumeration of every active set with SVD pseudo-inverses, and projected gradient.
#include <Eigen/Dense>

namespace spidar::reference {

struct TensionReference {
  Eigen::VectorXd t;
  double objective = 0;  ///< ‖U t − f‖²
  int candidates = 0;    ///< feasible active sets seen (brute force) or iterations (gradient)
};

/// Brute force: every string at its lower bound, upper bound or free (3^N sets); free tensions
/// are the minimum-norm least-squares solution (JacobiSVD pseudo-inverse). Among feasible sets,
/// the least objective, then the least norm. Exact up to rounding; N ≤ 8.
TensionReference brute_force_tensions(const Eigen::MatrixXd& U, const Eigen::Vector3d& f,
                                      double lo, double hi);

/// Accelerated projected gradient (FISTA) on the objective from t = lo, until the step is below
/// `tol` [N] or `max_iterations`. A generic solver: converges to an optimum, not necessarily the
/// least-norm one when N > 3.
TensionReference projected_gradient_tensions(const Eigen::MatrixXd& U, const Eigen::Vector3d& f,
                                             double lo, double hi, double tol = 1e-12,
                                             int max_iterations = 200000);

}  // namespace spidar::reference
