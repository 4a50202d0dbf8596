#include "spidar/registration/shape_estimator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "spidar/core/realtime.hpp"
#include "spidar/core/result.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration {

ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled) {
  if (!node.is_map()) node.fail("expected a map of personalisation settings");
  node.expect_keys({"enabled", "prior_sigma_length_m", "prior_sigma_width_m", "keyframes",
                    "min_pose_change", "solve_every", "min_keyframes", "iterations",
                    "freeze_sigma_length_m", "freeze_sigma_width_m", "max_relative_change",
                    "reach_min_miss_m", "apply_after_frames", "silhouette"});
  ShapeEstimatorParams p;
  if (auto b = node.find("enabled"); b && enabled) *enabled = b->as_bool();
  if (auto b = node.find("silhouette")) p.silhouette = b->as_bool();
  struct Field {
    const char* key;
    double ShapeEstimatorParams::*v;
    double lo, hi;            // (lo, hi], or [lo, hi] with zero_ok
    bool zero_ok = false;     // lo itself allowed (0 = never)
  };
  static constexpr Field kFields[] = {
      {"prior_sigma_length_m", &ShapeEstimatorParams::prior_sigma_length_m, 0.0, 0.1},
      {"prior_sigma_width_m", &ShapeEstimatorParams::prior_sigma_width_m, 0.0, 0.1},
      {"min_pose_change", &ShapeEstimatorParams::min_pose_change, 0.0, 10.0},
      {"freeze_sigma_length_m", &ShapeEstimatorParams::freeze_sigma_length_m, 0.0, 0.1},
      {"freeze_sigma_width_m", &ShapeEstimatorParams::freeze_sigma_width_m, 0.0, 0.1},
      {"max_relative_change", &ShapeEstimatorParams::max_relative_change, 0.0, 0.5},
      {"reach_min_miss_m", &ShapeEstimatorParams::reach_min_miss_m, 0.0, 0.05, true},
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
      {"apply_after_frames", &ShapeEstimatorParams::apply_after_frames, 0, 100},
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
    if (!(std::isfinite(v) && (v > f.lo || (f.zero_ok && v == f.lo)) && v <= f.hi))
      child->fail("expected a value in " + std::string(f.zero_ok ? "[" : "(") + std::to_string(f.lo) +
                  ", " + std::to_string(f.hi) + "], got " + std::to_string(v));
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

ShapeEstimator::Solve ShapeEstimator::run_solve(Solve job) {
  const ShapeEstimatorParams& p = job.params;
  const RegistrationParams& fit_params = job.fit_params;
  const vision::Camera* camera = job.camera ? &*job.camera : nullptr;
  hand::HandModel& model = job.model;
  ShapeEstimate& estimate = job.estimate;
  const double start_length_m = job.start_length_m, start_width_m = job.start_width_m;
  ImageEvidence skeleton_only;  // fingertips, bracelet wrist and a prior: no matte, no silhouette
  skeleton_only.camera = camera;
  const SuccessiveAdjustment solver(fit_params);
  const Eigen::Vector2d beta0(start_length_m, start_width_m);
  const Eigen::Matrix2d H0 = Eigen::Vector2d(1.0 / (p.prior_sigma_length_m * p.prior_sigma_length_m),
                                             1.0 / (p.prior_sigma_width_m * p.prior_sigma_width_m))
                                 .asDiagonal();
  const double h = p.difference_step_m;
  const double k = p.max_relative_change;
  Eigen::Vector2d beta(estimate.length_m, estimate.width_m);
  Eigen::Matrix2d H = H0;
  bool changed = false;
  for (int it = 0; it < p.iterations; ++it) {
    Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (Keyframe& kf : job.keyframes) {
      // The keyframe's pose at the current sizes (warm start, weak prior toward its last pose).
      ImageEvidence evidence = skeleton_only;
      if (!kf.owned.empty()) evidence.coverage = &kf.owned;
      hand::HandParams prior = kf.q;
      FitReport fit = solver.fit(model, kf.observation, evidence, &prior, &kf.q);
      if (p.reach_min_miss_m > 0 &&
          refit_reaching(solver, model, kf.observation, evidence, &prior,
                         {.min_miss_m = p.reach_min_miss_m}, &kf.q, &fit))
        prior = kf.q;  // the re-posed digits' prior moved along (refit_reaching)
      const ResidualProblem problem{&model, &kf.observation, &evidence, &prior, &fit_params};
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
          auto m = resized(model, beta.x() + (c == 0 ? sgn * h : 0.0), beta.y() + (c == 1 ? sgn * h : 0.0));
          if (!m) {
            ok = false;
            break;
          }
          const hand::HandModel mm = std::move(m).value();
          const ResidualProblem pk{&mm, &kf.observation, &evidence, &prior, &fit_params};
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
    const bool fl = estimate.length_frozen, fw = estimate.width_frozen;
    if (!fl && !fw) {
      step = H.ldlt().solve(rhs);
    } else if (!fl) {
      step.x() = rhs.x() / H(0, 0);
    } else if (!fw) {
      step.y() = rhs.y() / H(1, 1);
    }
    if (!step.allFinite()) break;
    const double L = std::clamp(beta.x() + step.x(), (1 - k) * start_length_m, (1 + k) * start_length_m);
    const double W = std::clamp(beta.y() + step.y(), (1 - k) * start_width_m, (1 + k) * start_width_m);
    auto m = resized(model, L, W);
    if (!m) break;  // outside the valid sizes: keep the last valid model
    const bool moved = std::abs(L - beta.x()) > 1e-7 || std::abs(W - beta.y()) > 1e-7;
    model = std::move(m).value();
    beta = Eigen::Vector2d(L, W);
    changed = changed || moved;
    if (step.norm() < 1e-6) break;
  }
  ++estimate.solves;
  estimate.length_m = beta.x();
  estimate.width_m = beta.y();
  const Eigen::Matrix2d cov = H.inverse();
  estimate.sigma_length_m = std::sqrt(std::max(cov(0, 0), 0.0));
  estimate.sigma_width_m = std::sqrt(std::max(cov(1, 1), 0.0));
  if (estimate.sigma_length_m < p.freeze_sigma_length_m) estimate.length_frozen = true;
  if (estimate.sigma_width_m < p.freeze_sigma_width_m) estimate.width_frozen = true;
  job.changed = changed;
  return job;
}

ShapeEstimator::~ShapeEstimator() {
  if (pending_.valid()) pending_.wait();
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
  Keyframe kf{q, observation, {}};
  if (p_.silhouette && image.coverage != nullptr) kf.owned = *image.coverage;
  const auto cap = static_cast<std::size_t>(std::max(p_.keyframes, 1));
  if (keyframes_.size() < cap) {
    keyframes_.push_back(kf);
  } else {
    keyframes_[next_slot_] = kf;
    next_slot_ = (next_slot_ + 1) % cap;
  }
  estimate_.keyframes = static_cast<int>(keyframes_.size());
  if (++new_since_solve_ < p_.solve_every || estimate_.keyframes < p_.min_keyframes) return false;
  if (pending_.valid()) return false;  // one re-estimate at a time: the next frame's offer starts it
  new_since_solve_ = 0;
  Solve job = make_solve(image.camera, fit_params);
  if (p_.apply_after_frames <= 0) return apply(run_solve(std::move(job)));
  polls_since_start_ = 0;
  pending_ = std::async(std::launch::async, [job = std::move(job)]() mutable {
    (void)core::set_nice(0);  // best effort: an ordinary share, below the frame thread's
    return run_solve(std::move(job));
  });
  return false;
}

bool ShapeEstimator::poll() {
  if (!pending_.valid()) return false;
  if (++polls_since_start_ < p_.apply_after_frames) return false;
  return apply(pending_.get());
}

ShapeEstimator::Solve ShapeEstimator::make_solve(const vision::Camera* camera,
                                                 const RegistrationParams& fit_params) const {
  Solve job;
  job.params = p_;
  job.fit_params = fit_params;
  if (camera != nullptr) job.camera = *camera;
  job.model = model_;
  job.start_length_m = start_length_m_;
  job.start_width_m = start_width_m_;
  job.keyframes = keyframes_;
  job.estimate = estimate_;
  return job;
}

bool ShapeEstimator::apply(Solve&& done) {
  model_ = std::move(done.model);
  const int keyframes = estimate_.keyframes;
  estimate_ = done.estimate;
  estimate_.keyframes = keyframes;
  // The keyframes' refitted poses warm-start the next re-estimate, unless keyframes came since it
  // started (new_since_solve_ counts them from its start).
  if (new_since_solve_ == 0) keyframes_ = std::move(done.keyframes);
  return done.changed;
}

}  // namespace spidar::registration
