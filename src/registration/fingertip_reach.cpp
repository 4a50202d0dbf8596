#include "spidar/registration/fingertip_reach.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "spidar/hand/kinematics.hpp"

namespace spidar::registration {
namespace {

/// A digit ends nearer its fingertip by at least this before it changes [m].
constexpr double kMinGain = 1e-5;
/// A cap this near its fingertip has reached it: no further steps or starts [m].
constexpr double kReached = 1e-6;
/// The range searched for a parameter the model leaves unlimited [rad].
constexpr double kDefaultLow = -0.2;
constexpr double kDefaultHigh = 1.8;

/// One digit's own parameter columns (2 or 3).
struct DigitColumns {
  std::array<int, 3> col{};
  int n = 0;
};

DigitColumns digit_columns(int finger) {
  const hand::DigitParams p = hand::digit_params(finger);
  DigitColumns c;
  c.col[static_cast<std::size_t>(c.n++)] = p.flexion;
  if (p.abduction >= 0) c.col[static_cast<std::size_t>(c.n++)] = p.abduction;
  c.col[static_cast<std::size_t>(c.n++)] = p.distal;
  return c;
}

double clamp_param(double v, const hand::ParamLimits& lim, int k) {
  return std::clamp(v, lim.lower[k], lim.upper[k]);
}

/// Damped Gauss-Newton on the digit's own columns from `x`; returns the final miss [m].
double descend(const hand::HandModel& model, int finger, const DigitColumns& dc, const Vec3& target,
               int iterations, hand::HandParams* x) {
  hand::HandPoints pts;
  hand::FingertipJacobian J;
  hand::forward_kinematics(model, *x, &pts, &J, nullptr);
  Vec3 r = pts.p_W_fingertip[static_cast<std::size_t>(finger)] - target;
  double miss = r.norm();
  double lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d Jd = Eigen::Matrix3d::Zero();
    for (int i = 0; i < dc.n; ++i) Jd.col(i) = J.block<3, 1>(3 * finger, dc.col[static_cast<std::size_t>(i)]);
    Eigen::Matrix3d A = Jd.transpose() * Jd;
    const Vec3 g = Jd.transpose() * r;
    for (int i = dc.n; i < 3; ++i) A(i, i) = 1.0;  // unused column: δ = 0 there
    Eigen::Matrix3d M = A;
    M.diagonal() += lambda * A.diagonal() + Vec3::Constant(1e-12);
    const Vec3 delta = M.ldlt().solve(-g);
    if (!delta.allFinite()) break;
    hand::HandParams cand = *x;
    for (int i = 0; i < dc.n; ++i) {
      const int k = dc.col[static_cast<std::size_t>(i)];
      cand[k] = clamp_param(cand[k] + delta[i], model.limits, k);
    }
    hand::forward_kinematics(model, cand, &pts, nullptr, nullptr);
    const Vec3 cr = pts.p_W_fingertip[static_cast<std::size_t>(finger)] - target;
    if (cr.norm() < miss) {
      *x = cand;
      r = cr;
      miss = cr.norm();
      lambda = std::max(lambda / 10.0, 1e-9);
      if (miss < kReached) break;
      hand::forward_kinematics(model, *x, &pts, &J, nullptr);
    } else {
      lambda = std::min(lambda * 10.0, 1e9);
    }
  }
  return miss;
}

}  // namespace

int FingertipReach::changed_count() const {
  return static_cast<int>(std::count(changed.begin(), changed.end(), true));
}

std::array<double, hand::kFingertipCount> fingertip_misses(const hand::HandModel& model,
                                                           const HandObservation& observation,
                                                           const hand::HandParams& q) {
  std::array<double, hand::kFingertipCount> miss{};
  hand::HandPoints pts;
  hand::forward_kinematics(model, q, &pts, nullptr, nullptr);
  for (std::size_t f = 0; f < miss.size(); ++f) {
    const Vec3& target = observation.p_W_fingertip[f];
    if (observation.fingertip_valid[f] && target.allFinite()) miss[f] = (pts.p_W_fingertip[f] - target).norm();
  }
  return miss;
}

FingertipReach reach_fingertips(const hand::HandModel& model, const HandObservation& observation,
                                const FingertipReachParams& params, hand::HandParams* q) {
  FingertipReach out;
  if (q == nullptr || !q->q.allFinite()) return out;
  const int starts = std::max(params.starts, 2);
  const int iterations = std::max(params.iterations, 1);
  out.miss_before_m = fingertip_misses(model, observation, *q);
  out.miss_after_m = out.miss_before_m;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    const Vec3& target = observation.p_W_fingertip[fs];
    if (!observation.fingertip_valid[fs] || !target.allFinite()) continue;
    if (!(out.miss_before_m[fs] > params.min_miss_m)) continue;
    const DigitColumns dc = digit_columns(f);
    const int distal = dc.col[static_cast<std::size_t>(dc.n - 1)];
    double lo = model.limits.lower[distal], hi = model.limits.upper[distal];
    if (!std::isfinite(lo)) lo = kDefaultLow;
    if (!std::isfinite(hi)) hi = kDefaultHigh;

    const int flexion = dc.col[0];
    double flo = model.limits.lower[flexion], fhi = model.limits.upper[flexion];
    if (!std::isfinite(flo)) flo = kDefaultLow;
    if (!std::isfinite(fhi)) fhi = kDefaultHigh;

    hand::HandParams best = *q;
    double best_miss = out.miss_before_m[fs];
    // Starts: the current pose, then the distal angle across its range, each with the current
    // flexion and with the flexion at a quarter and three quarters of its range.
    for (int s = -1; s < 3 * starts; ++s) {
      hand::HandParams x = *q;
      if (s >= 0) {
        x[distal] = lo + (hi - lo) * (s % starts) / (starts - 1);
        if (s / starts == 1) x[flexion] = flo + 0.25 * (fhi - flo);
        if (s / starts == 2) x[flexion] = flo + 0.75 * (fhi - flo);
      }
      const double m = descend(model, f, dc, target, iterations, &x);
      if (m < best_miss - kMinGain) {
        best_miss = m;
        best = x;
      }
      if (best_miss < kReached) break;
    }
    if (best_miss < out.miss_before_m[fs] - kMinGain && best_miss > kReached)
      best_miss = descend(model, f, dc, target, params.polish_iterations, &best);
    if (best_miss < out.miss_before_m[fs] - kMinGain) {
      *q = best;
      out.changed[fs] = true;
      out.miss_after_m[fs] = best_miss;
    }
  }
  return out;
}

bool refit_reaching(const SuccessiveAdjustment& solver, const hand::HandModel& model,
                    const HandObservation& observation, const ImageEvidence& image,
                    const hand::HandParams* prior, const FingertipReachParams& reach,
                    hand::HandParams* q, FitReport* report) {
  if (q == nullptr || report == nullptr) return false;
  hand::HandParams q2 = *q;
  const FingertipReach moved = reach_fingertips(model, observation, reach, &q2);
  if (moved.changed_count() == 0) return false;
  hand::HandParams prior2 = prior != nullptr ? *prior : q2;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    if (!moved.changed[static_cast<std::size_t>(f)]) continue;
    const DigitColumns dc = digit_columns(f);
    for (int i = 0; i < dc.n; ++i) prior2[dc.col[static_cast<std::size_t>(i)]] = q2[dc.col[static_cast<std::size_t>(i)]];
  }
  FitReport again = solver.fit(model, observation, image, prior != nullptr ? &prior2 : nullptr, &q2);
  const int iterations = report->iterations + again.iterations;
  const bool better = again.terms.evidence() < report->terms.evidence();
  if (better) {
    again.cost_initial = report->cost_initial;
    *report = again;
    *q = q2;
  }
  report->iterations = iterations;
  return better;
}

}  // namespace spidar::registration
