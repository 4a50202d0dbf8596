#include "spidar/registration/shape_estimator.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <string>

#include "spidar/core/result.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration {

ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled) {
  if (!node.is_map()) node.fail("expected a map of personalisation settings");
  node.expect_keys({"enabled", "prior_sigma_length_m", "prior_sigma_width_m", "frame_weight", "forgetting",
                    "min_pose_change", "freeze_sigma_length_m", "freeze_sigma_width_m",
                    "max_step_m", "max_relative_change"});
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
      {"frame_weight", &ShapeEstimatorParams::frame_weight, 0.0, 1.0},
      {"forgetting", &ShapeEstimatorParams::forgetting, 0.0, 1.0},
      {"min_pose_change", &ShapeEstimatorParams::min_pose_change, 0.0, 10.0},
      {"freeze_sigma_length_m", &ShapeEstimatorParams::freeze_sigma_length_m, 0.0, 0.1},
      {"freeze_sigma_width_m", &ShapeEstimatorParams::freeze_sigma_width_m, 0.0, 0.1},
      {"max_step_m", &ShapeEstimatorParams::max_step_m, 0.0, 0.05},
      {"max_relative_change", &ShapeEstimatorParams::max_relative_change, 0.0, 0.5},
  };
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
  H_(0, 0) = 1.0 / (p_.prior_sigma_length_m * p_.prior_sigma_length_m);
  H_(1, 1) = 1.0 / (p_.prior_sigma_width_m * p_.prior_sigma_width_m);
  estimate_.length_m = start_length_m_ = start.shape.dimensions.length;
  estimate_.width_m = start_width_m_ = start.shape.dimensions.width;
  estimate_.sigma_length_m = p_.prior_sigma_length_m;
  estimate_.sigma_width_m = p_.prior_sigma_width_m;
}

bool ShapeEstimator::add_frame(const hand::HandParams& q, const HandObservation& observation,
                               const ImageEvidence& image, const hand::HandParams* prior,
                               const RegistrationParams& fit_params) {
  if (estimate_.length_frozen && estimate_.width_frozen) return false;
  if (!q.q.allFinite()) return false;
  if (have_last_ && (q.q - last_used_.q).norm() < p_.min_pose_change) return false;
  int tips = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f)
    tips += observation.fingertip_valid[f] && observation.p_W_fingertip[f].allFinite() ? 1 : 0;
  if (tips < 3) return false;  // too little of the hand measured to tell its size

  // The skeleton's terms only: fingertips, bracelet wrist, temporal prior (no matte, no
  // silhouette distance: no joint-balls, no silhouette term).
  ImageEvidence skeleton_only;
  skeleton_only.camera = image.camera;
  const ResidualProblem problem{&model_, &observation, &skeleton_only, prior, &fit_params};
  FrozenTargets targets;
  freeze_targets(problem, q, &targets);
  VecX r;
  MatX J;
  stacked_residuals(problem, targets, q, &r, &J);

  // J_β by central differences of the model's sizes, with the same frozen targets.
  MatX Jb(r.size(), 2);
  const double h = p_.difference_step_m;
  for (int k = 0; k < 2; ++k) {
    VecX rp, rm;
    for (int sgn : {1, -1}) {
      const double dl = k == 0 ? sgn * h : 0.0, dw = k == 1 ? sgn * h : 0.0;
      auto m = resized(model_, estimate_.length_m + dl, estimate_.width_m + dw);
      if (!m) return false;
      const hand::HandModel mm = std::move(m).value();
      const ResidualProblem pk{&mm, &observation, &skeleton_only, prior, &fit_params};
      stacked_residuals(pk, targets, q, sgn > 0 ? &rp : &rm, nullptr);
    }
    if (rp.size() != r.size() || rm.size() != r.size()) return false;
    Jb.col(k) = (rp - rm) / (2.0 * h);
  }
  if (!J.allFinite() || !Jb.allFinite() || !r.allFinite()) return false;

  // Marginalise the pose: S = JbᵀJb − JbᵀJ A⁻¹ JᵀJb, g = −(Jbᵀr − JbᵀJ A⁻¹ Jᵀr).
  MatX A = J.transpose() * J;
  A.diagonal().array() += 1e-9 * std::max(1.0, A.diagonal().maxCoeff());
  const Eigen::LDLT<MatX> A_ldlt(A);
  const MatX AJtJb = A_ldlt.solve(J.transpose() * Jb);
  const VecX AJtr = A_ldlt.solve(J.transpose() * r);
  const Eigen::Matrix2d S = Jb.transpose() * Jb - (Jb.transpose() * J) * AJtJb;
  const Eigen::Vector2d g = -(Jb.transpose() * r - (Jb.transpose() * J) * AJtr);
  if (!S.allFinite() || !g.allFinite()) return false;

  const double w = p_.frame_weight;
  // Forget old evidence, but never below the prior's information.
  Eigen::Matrix2d H = p_.forgetting * H_ + w * S;
  H(0, 0) = std::max(H(0, 0), 1.0 / (p_.prior_sigma_length_m * p_.prior_sigma_length_m));
  H(1, 1) = std::max(H(1, 1), 1.0 / (p_.prior_sigma_width_m * p_.prior_sigma_width_m));
  Eigen::Vector2d step = Eigen::Vector2d::Zero();
  const bool fl = estimate_.length_frozen, fw = estimate_.width_frozen;
  if (!fl && !fw) {
    step = H.ldlt().solve(w * g);
  } else if (!fl) {
    step.x() = w * g.x() / H(0, 0);
  } else {
    step.y() = w * g.y() / H(1, 1);
  }
  if (!step.allFinite()) return false;
  step = step.cwiseMax(-p_.max_step_m).cwiseMin(p_.max_step_m);
  H_ = H;
  last_used_ = q;
  have_last_ = true;
  ++estimate_.frames_used;

  const Eigen::Matrix2d cov = H_.inverse();
  estimate_.sigma_length_m = std::sqrt(std::max(cov(0, 0), 0.0));
  estimate_.sigma_width_m = std::sqrt(std::max(cov(1, 1), 0.0));
  if (step.norm() == 0.0) return false;
  const double L0 = start_length_m_, W0 = start_width_m_, k = p_.max_relative_change;
  const double L = std::clamp(estimate_.length_m + step.x(), (1 - k) * L0, (1 + k) * L0);
  const double W = std::clamp(estimate_.width_m + step.y(), (1 - k) * W0, (1 + k) * W0);
  auto m = resized(model_, L, W);
  if (!m) return false;  // outside the valid sizes: keep the last valid model
  model_ = std::move(m).value();
  estimate_.length_m = model_.shape.dimensions.length;
  estimate_.width_m = model_.shape.dimensions.width;
  if (estimate_.sigma_length_m < p_.freeze_sigma_length_m) estimate_.length_frozen = true;
  if (estimate_.sigma_width_m < p_.freeze_sigma_width_m) estimate_.width_frozen = true;
  return true;
}

}  // namespace spidar::registration
