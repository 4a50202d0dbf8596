#include "spidar/registration/successive_adjustment.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "residual_terms.hpp"
#include "spidar/core/result.hpp"

namespace spidar::registration {
namespace {

using MatParams = Eigen::Matrix<double, hand::kParamCount, hand::kParamCount>;

/// λ never drops below / rises above these (a rejected step at λ = 0 must still grow it).
constexpr double kLambdaMin = 1e-9;
constexpr double kLambdaMax = 1e9;

/// Solves (A + λ diag(A) + ε I) Δ = b. The tiny ridge ε keeps directions no term observes (e.g.
/// all image terms off and no prior) at Δ = 0, which is what A⁺b gives there.
hand::ParamVec damped_step(const MatParams& A, const hand::ParamVec& b, double lambda) {
  MatParams M = A;
  const double ridge = 1e-12 * std::max(1.0, A.diagonal().maxCoeff());
  M.diagonal().array() += lambda * A.diagonal().array() + ridge;
  return M.ldlt().solve(b);
}

}  // namespace

SuccessiveAdjustment::SuccessiveAdjustment(const RegistrationParams& params) : params_(params) {
  if (auto s = validate(params); !s.ok()) throw SpidarError(s.error().message);
}

FitReport SuccessiveAdjustment::fit(const hand::HandModel& model,
                                    const HandObservation& observation,
                                    const ImageEvidence& image, const hand::HandParams* prior,
                                    hand::HandParams* params) const {
  FitReport report;
  const RegistrationParams& rp = params_;
  const ResidualProblem problem{&model, &observation, &image, prior, &rp};

  hand::HandParams q = *params;
  // The little finger moves on its own with our method (little_free and the silhouette term that
  // observes it), starting from the ring finger's angles if it copied them; else it copies them.
  const bool free_little = little_moves_freely(rp);
  if (free_little && !q.little_independent) q.set_little(q.ring());
  q.little_independent = free_little;
  q = hand::clamp_to_limits(q, model.limits);
  FrozenTargets targets;
  detail::PoseState state;
  detail::NormalEquationsSink eq;
  double lambda = rp.lambda_initial;
  bool fresh = false;  // targets and normal equations belong to q
  double cost = 0;

  for (int it = 0; it < rp.max_iterations; ++it) {
    if (!fresh) {
      freeze_targets(problem, q, &targets);
      detail::pose_state(model, q, true, &state);
      eq = detail::NormalEquationsSink{};
      detail::visit_residuals<true>(problem, targets, q, state, eq);
      cost = eq.costs.total();
      fresh = true;
      if (it == 0) report.cost_initial = cost;
    }
    if (cost < rp.cost_epsilon) {
      report.converged = true;
      break;
    }
    ++report.iterations;
    const hand::ParamVec delta = damped_step(eq.A, eq.b, lambda);
    if (!delta.allFinite()) {
      lambda = std::min(std::max(lambda, kLambdaMin) * 10.0, kLambdaMax);
      continue;
    }
    hand::HandParams candidate = q;
    candidate.q += delta;
    candidate = hand::clamp_to_limits(candidate, model.limits);
    const double step = (candidate.q - q.q).norm();
    const double candidate_cost = term_costs(problem, targets, candidate).total();
    if (candidate_cost < cost) {
      const bool small_gain = cost - candidate_cost < rp.relative_epsilon * cost;
      q = candidate;
      fresh = false;
      if (small_gain) {
        report.converged = true;
        break;
      }
      lambda /= 10.0;
      if (lambda < kLambdaMin) lambda = rp.lambda_initial > 0.0 ? kLambdaMin : 0.0;
    } else {
      lambda = std::min(std::max(lambda, kLambdaMin) * 10.0, kLambdaMax);
    }
    if (step < rp.step_epsilon) {
      report.converged = true;
      break;
    }
  }

  // The costs at the final pose, with the image targets recomputed there.
  if (!fresh) freeze_targets(problem, q, &targets);
  report.terms = term_costs(problem, targets, q);
  report.cost_final = report.terms.total();
  *params = q;
  return report;
}

}  // namespace spidar::registration
