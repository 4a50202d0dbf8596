#include "spidar/registration/shape_estimator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "spidar/core/result.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration {

ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled) {
  if (!node.is_map()) node.fail("expected a map of personalisation settings");
  node.expect_keys({"enabled", "prior_sigma_length_m", "prior_sigma_width_m", "keyframes",
                    "min_pose_change", "solve_every", "min_keyframes", "iterations",
                    "freeze_sigma_length_m", "freeze_sigma_width_m", "max_relative_change"});
  ShapeEstimatorParams p;
  if (auto b = node.find("enabled"); b && enabled) *enabled = b->as_bool();
  struct Field {
    const char* key;
    double ShapeEstimatorParams::*v;
    double lo, hi;  // (lo, hi]
  };
  static constexpr Field kFields[] = {
      {"prior_sigma_length_m", &ShapeEstimatorParams::prior_sigma_length_m, 0.0, 0.1},
      {"prior_sigma_width_m", &ShapeEstimatorParams::prior_sigma_width_m, 0.0, 0.1},
      {"min_pose_change", &ShapeEstimatorParams::min_pose_change, 0.0, 10.0},
      {"freeze_sigma_length_m", &ShapeEstimatorParams::freeze_sigma_length_m, 0.0, 0.1},
      {"freeze_sigma_width_m", &ShapeEstimatorParams::freeze_sigma_width_m, 0.0, 0.1},
      {"max_relative_change", &ShapeEstimatorParams::max_relative_change, 0.0, 0.5},
  };
  struct IntField {
    const char* key;
    int ShapeEstimatorParams::*v;
    int lo, hi;  // [lo, hi]
  };
  static constexpr IntField kInts[] = {
      {"keyframes", &ShapeEstimatorParams::keyframes, 2, 200},
      {"solve_every", &ShapeEstimatorParams::solve_every, 1, 1000},
      {"min_keyframes", &ShapeEstimatorParams::min_keyframes, 1, 200},
      {"iterations", &ShapeEstimatorParams::iterations, 1, 50},
  };
  for (const IntField& f : kInts) {
    const auto child = node.find(f.key);
    if (!child) continue;
    const std::int64_t v = child->as_int();
    if (v < f.lo || v > f.hi)
      child->fail("expected an integer in [" + std::to_string(f.lo) + ", " + std::to_string(f.hi) +
                  "], got " + std::to_string(v));
    p.*f.v = static_cast<int>(v);
  }
  for (const Field& f : kFields) {
    const auto child = node.find(f.key);
    if (!child) continue;
    const double v = child->as_double();
    if (!(std::isfinite(v) && v > f.lo && v <= f.hi))
      child->fail("expected a value in (" + std::to_string(f.lo) + ", " + std::to_string(f.hi) +
                  "], got " + std::to_string(v));
    p.*f.v = v;
  }
  return p;
}

Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m) {
  hand::HandDimensions d = m.shape.dimensions;
  d.length = length_m;
  d.width = width_m;
  auto shape = hand::make_hand_shape(d);
  if (!shape) return shape.error();
  hand::HandModel out = m;
  out.shape = std::move(shape).value();
  return out;
}

ShapeEstimator::ShapeEstimator(const hand::HandModel& start, const ShapeEstimatorParams& params)
    : p_(params), model_(start) {
  estimate_.length_m = start_length_m_ = start.shape.dimensions.length;
  estimate_.width_m = start_width_m_ = start.shape.dimensions.width;
  estimate_.sigma_length_m = p_.prior_sigma_length_m;
  estimate_.sigma_width_m = p_.prior_sigma_width_m;
}

bool ShapeEstimator::add_frame(const hand::HandParams& q, const HandObservation& observation,
                               const ImageEvidence& image, const RegistrationParams& fit_params) {
  if (estimate_.length_frozen && estimate_.width_frozen) return false;
  if (!q.q.allFinite()) return false;
  int tips = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f)
    tips += observation.fingertip_valid[f] && observation.p_W_fingertip[f].allFinite() ? 1 : 0;
  if (tips < hand::kFingertipCount) return false;  // only fully measured hands make keyframes
  for (const Keyframe& k : keyframes_)
    if ((k.q.q - q.q).norm() < p_.min_pose_change) return false;  // nothing new
  const Keyframe kf{q, observation};
  const auto cap = static_cast<std::size_t>(std::max(p_.keyframes, 1));
  if (keyframes_.size() < cap) {
    keyframes_.push_back(kf);
  } else {
    keyframes_[next_slot_] = kf;
    next_slot_ = (next_slot_ + 1) % cap;
  }
  estimate_.keyframes = static_cast<int>(keyframes_.size());
  if (++new_since_solve_ < p_.solve_every || estimate_.keyframes < p_.min_keyframes) return false;
  new_since_solve_ = 0;
  return solve(image.camera, fit_params);
}

bool ShapeEstimator::solve(const vision::Camera* camera, const RegistrationParams& fit_params) {
  ImageEvidence skeleton_only;  // fingertips, bracelet wrist and a prior: no matte, no silhouette
  skeleton_only.camera = camera;
  const SuccessiveAdjustment solver(fit_params);
  const Eigen::Vector2d beta0(start_length_m_, start_width_m_);
  const Eigen::Matrix2d H0 = Eigen::Vector2d(1.0 / (p_.prior_sigma_length_m * p_.prior_sigma_length_m),
                                             1.0 / (p_.prior_sigma_width_m * p_.prior_sigma_width_m))
                                 .asDiagonal();
  const double h = p_.difference_step_m;
  const double k = p_.max_relative_change;
  Eigen::Vector2d beta(estimate_.length_m, estimate_.width_m);
  Eigen::Matrix2d H = H0;
  bool changed = false;
  for (int it = 0; it < p_.iterations; ++it) {
    Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (Keyframe& kf : keyframes_) {
      // The keyframe's pose at the current sizes (warm start, weak prior toward its last pose).
      hand::HandParams prior = kf.q;
      FitReport fit = solver.fit(model_, kf.observation, skeleton_only, &prior, &kf.q);
      if (p_.reach_min_miss_m > 0 &&
          refit_reaching(solver, model_, kf.observation, skeleton_only, &prior,
                         {.min_miss_m = p_.reach_min_miss_m}, &kf.q, &fit))
        prior = kf.q;  // the re-posed digits' prior moved along (refit_reaching)
      const ResidualProblem problem{&model_, &kf.observation, &skeleton_only, &prior, &fit_params};
      FrozenTargets targets;
      freeze_targets(problem, kf.q, &targets);
      VecX r;
      MatX J;
      stacked_residuals(problem, targets, kf.q, &r, &J);
      MatX Jb(r.size(), 2);
      bool ok = true;
      for (int c = 0; c < 2 && ok; ++c) {
        VecX rp, rm;
        for (int sgn : {1, -1}) {
          auto m = resized(model_, beta.x() + (c == 0 ? sgn * h : 0.0), beta.y() + (c == 1 ? sgn * h : 0.0));
          if (!m) {
            ok = false;
            break;
          }
          const hand::HandModel mm = std::move(m).value();
          const ResidualProblem pk{&mm, &kf.observation, &skeleton_only, &prior, &fit_params};
          stacked_residuals(pk, targets, kf.q, sgn > 0 ? &rp : &rm, nullptr);
        }
        ok = ok && rp.size() == r.size() && rm.size() == r.size();
        if (ok) Jb.col(c) = (rp - rm) / (2.0 * h);
      }
      if (!ok || !J.allFinite() || !Jb.allFinite() || !r.allFinite()) continue;
      // Marginalise the pose (Schur complement).
      MatX A = J.transpose() * J;
      A.diagonal().array() += 1e-9 * std::max(1.0, A.diagonal().maxCoeff());
      const Eigen::LDLT<MatX> A_ldlt(A);
      const MatX JtJb = J.transpose() * Jb;
      const MatX JbtJ = JtJb.transpose();
      S += Jb.transpose() * Jb - JbtJ * A_ldlt.solve(JtJb);
      g -= Jb.transpose() * r - JbtJ * A_ldlt.solve(J.transpose() * r);
    }
    H = S + H0;
    const Eigen::Vector2d rhs = g + H0 * (beta0 - beta);
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    const bool fl = estimate_.length_frozen, fw = estimate_.width_frozen;
    if (!fl && !fw) {
      step = H.ldlt().solve(rhs);
    } else if (!fl) {
      step.x() = rhs.x() / H(0, 0);
    } else if (!fw) {
      step.y() = rhs.y() / H(1, 1);
    }
    if (!step.allFinite()) break;
    const double L = std::clamp(beta.x() + step.x(), (1 - k) * start_length_m_, (1 + k) * start_length_m_);
    const double W = std::clamp(beta.y() + step.y(), (1 - k) * start_width_m_, (1 + k) * start_width_m_);
    auto m = resized(model_, L, W);
    if (!m) break;  // outside the valid sizes: keep the last valid model
    const bool moved = std::abs(L - beta.x()) > 1e-7 || std::abs(W - beta.y()) > 1e-7;
    model_ = std::move(m).value();
    beta = Eigen::Vector2d(L, W);
    changed = changed || moved;
    if (step.norm() < 1e-6) break;
  }
  ++estimate_.solves;
  estimate_.length_m = beta.x();
  estimate_.width_m = beta.y();
  const Eigen::Matrix2d cov = H.inverse();
  estimate_.sigma_length_m = std::sqrt(std::max(cov(0, 0), 0.0));
  estimate_.sigma_width_m = std::sqrt(std::max(cov(1, 1), 0.0));
  if (estimate_.sigma_length_m < p_.freeze_sigma_length_m) estimate_.length_frozen = true;
  if (estimate_.sigma_width_m < p_.freeze_sigma_width_m) estimate_.width_frozen = true;
  return changed;
}

}  // namespace spidar::registration
