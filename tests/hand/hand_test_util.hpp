#pragma once
// Shared helpers of the hand tests: random poses within limits and central differences.
#include <algorithm>
#include <random>

#include "spidar/hand/kinematics.hpp"

namespace spidar::hand::testing {

/// A random pose: fingers uniform within the model's limits, wrist anywhere near the frame
/// centre with a rotation vector of norm up to `max_rotation` [rad].
inline HandParams random_params(const HandModel& model, std::mt19937& rng,
                                double max_rotation = 3.0) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  HandParams p;
  for (int i = kThumbCmcFlexion; i < kParamCount; ++i) {
    const double lo = model.limits.lower[i];
    const double hi = model.limits.upper[i];
    p.q[i] = lo + (hi - lo) * unit(rng);
  }
  const Vec3 p_W(0.3 * (unit(rng) - 0.5), 0.3 * (unit(rng) - 0.5), 0.3 * (unit(rng) - 0.5));
  Vec3 axis(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
  axis.normalize();
  p.set_wrist(p_W, axis * (max_rotation * unit(rng)));
  return p;
}

/// Central differences of a stacked function of the parameters, step h.
template <int Rows, typename F>
Eigen::Matrix<double, Rows, kParamCount> central_differences(const HandParams& params, F f,
                                                             double h = 1e-6) {
  Eigen::Matrix<double, Rows, kParamCount> J;
  for (int i = 0; i < kParamCount; ++i) {
    HandParams plus = params;
    HandParams minus = params;
    plus.q[i] += h;
    minus.q[i] -= h;
    J.col(i) = (f(plus) - f(minus)) / (2.0 * h);
  }
  return J;
}

/// max |A − B| / max(max |B|, floor): the relative error the tests bound by 1e-6.
template <typename A, typename B>
double relative_error(const A& analytic, const B& reference, double floor = 1e-3) {
  const double scale = std::max(reference.cwiseAbs().maxCoeff(), floor);
  return (analytic - reference).cwiseAbs().maxCoeff() / scale;
}

}  // namespace spidar::hand::testing
