#include "spidar/registration/shape_estimator.hpp"
#include "spidar/core/thread_name.hpp"

#include <Eigen/Cholesky>
#include <opencv2/core.hpp>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "spidar/core/realtime.hpp"
#include "spidar/core/result.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/palm_breadth.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/vision/silhouette.hpp"

namespace spidar::registration {
namespace {
/// The keyframes' distance transforms cover their silhouette's bounding box grown by this [px]
/// (as the frame pipeline's, FramePipelineParams::silhouette_margin_px).
constexpr int kSilhouetteMarginPx = 40;
/// A digit's section is evidence on its thickness when the model's diameter is within this factor
/// of it either way (wider: two fingers side by side; narrower: a finger partly hidden).
constexpr double kSectionMaxRatio = 1.35;
/// The digits' sections pooled (ShapeEstimatorParams::digit_section_sigma): the oldest go first.
constexpr std::size_t kMaxSectionSizes = 400;
/// The fingertips' reaches pooled (ShapeEstimatorParams::cap_offset_from_image): the oldest go first.
constexpr std::size_t kMaxCapReaches = 400;
/// The models are rebuilt for a new cap offset only when it moved by this much [m].
constexpr double kCapReachStepM = 1e-4;
/// A section's edges lie at least this far outside every other part of the hand's outline [px]
/// (ShapeEstimatorParams::digit_section_clear_edges): an edge found on another part's own boundary,
/// the far side of a neighbour the digit merges with in the matte, lies within a pixel or so of it.
constexpr double kSectionClearancePx = 2.0;
}  // namespace

ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled) {
  if (!node.is_map()) node.fail("expected a map of personalisation settings");
  node.expect_keys({"enabled", "prior_sigma_length_m", "prior_sigma_width_m", "prior_sigma_thickness",
                    "keyframes", "min_pose_change", "solve_every", "min_keyframes", "iterations",
                    "freeze_sigma_length_m", "freeze_sigma_width_m", "freeze_sigma_thickness",
                    "max_relative_change", "reach_min_miss_m", "apply_after_frames", "silhouette",
                    "max_fingertip_cost", "max_keyframe_speed_m_s", "shared_hands", "keyframe_prior_scale",
                    "keyframe_prior", "joint_balls", "palm_breadth_sigma_px", "palm_breadth_at",
                    "palm_breadth_min_facing", "digit_axes", "digit_section_sigma", "digit_section_clear_edges",
                    "keyframe_window", "accumulate", "cap_offset_from_image", "cap_offset_min_samples",
                    "cap_offset_max_change_m"});
  ShapeEstimatorParams p;
  if (auto b = node.find("enabled"); b && enabled) *enabled = b->as_bool();
  if (auto b = node.find("shared_hands")) p.shared_hands = b->as_bool();
  if (auto b = node.find("joint_balls")) p.joint_balls = b->as_bool();
  if (auto b = node.find("digit_axes")) p.digit_axes = b->as_bool();
  if (auto b = node.find("digit_section_clear_edges")) p.digit_section_clear_edges = b->as_bool();
  if (auto b = node.find("accumulate")) p.accumulate = b->as_bool();
  if (auto b = node.find("cap_offset_from_image")) p.cap_offset_from_image = b->as_bool();
  if (auto b = node.find("keyframe_prior")) {
    const std::string v = b->as_string();
    if (v == "taken") p.keyframe_prior = KeyframePrior::kTaken;
    else if (v == "last") p.keyframe_prior = KeyframePrior::kLast;
    else b->fail("expected taken or last, got '" + v + "'");
  }
  if (auto b = node.find("keyframe_window")) {
    const std::string v = b->as_string();
    if (v == "newest") p.keyframe_window = KeyframeWindow::kNewest;
    else if (v == "session") p.keyframe_window = KeyframeWindow::kSession;
    else b->fail("expected newest or session, got '" + v + "'");
  }
  if (auto b = node.find("silhouette")) {
    const std::string v = b->as_string();
    if (v == "none" || v == "false") p.silhouette = ShapeSilhouette::kNone;
    else if (v == "spill") p.silhouette = ShapeSilhouette::kSpill;
    else if (v == "both" || v == "true") p.silhouette = ShapeSilhouette::kBoth;
    else b->fail("expected none, spill or both, got '" + v + "'");
  }
  struct Field {
    const char* key;
    double ShapeEstimatorParams::*v;
    double lo, hi;            // (lo, hi]
    bool zero_ok = false;     // 0 allowed as well (0 = never, or off)
  };
  // A σ divides a residual: the lower bounds are the smallest that still mean a measurement
  // (below them a weight's square overflows the normal equations).
  static constexpr Field kFields[] = {
      {"prior_sigma_length_m", &ShapeEstimatorParams::prior_sigma_length_m, 1e-5, 0.1},
      {"prior_sigma_width_m", &ShapeEstimatorParams::prior_sigma_width_m, 1e-5, 0.1},
      {"prior_sigma_thickness", &ShapeEstimatorParams::prior_sigma_thickness, 1e-4, 1.0},
      {"min_pose_change", &ShapeEstimatorParams::min_pose_change, 0.0, 10.0},
      {"freeze_sigma_length_m", &ShapeEstimatorParams::freeze_sigma_length_m, 0.0, 0.1},
      {"freeze_sigma_width_m", &ShapeEstimatorParams::freeze_sigma_width_m, 0.0, 0.1},
      {"freeze_sigma_thickness", &ShapeEstimatorParams::freeze_sigma_thickness, 0.0, 1.0},
      {"max_relative_change", &ShapeEstimatorParams::max_relative_change, 0.0, 0.5},
      {"reach_min_miss_m", &ShapeEstimatorParams::reach_min_miss_m, 0.0, 0.05, true},
      {"max_fingertip_cost", &ShapeEstimatorParams::max_fingertip_cost, 0.0, 1e6},
      {"max_keyframe_speed_m_s", &ShapeEstimatorParams::max_keyframe_speed_m_s, 0.0, 100.0, true},
      {"keyframe_prior_scale", &ShapeEstimatorParams::keyframe_prior_scale, 1e-3, 1e3},
      {"palm_breadth_sigma_px", &ShapeEstimatorParams::palm_breadth_sigma_px, 0.01, 1e3, true},
      {"digit_section_sigma", &ShapeEstimatorParams::digit_section_sigma, 1e-3, 2.0, true},
      {"cap_offset_max_change_m", &ShapeEstimatorParams::cap_offset_max_change_m, 0.0, 0.01, true},
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
      {"cap_offset_min_samples", &ShapeEstimatorParams::cap_offset_min_samples, 1, 400},
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
  if (p.min_keyframes > p.keyframes) {
    const auto child = node.find("min_keyframes");
    (child ? *child : node)
        .fail("min_keyframes (" + std::to_string(p.min_keyframes) + ") must not exceed keyframes (" +
              std::to_string(p.keyframes) + "): the estimate would never start");
  }
  for (const Field& f : kFields) {
    const auto child = node.find(f.key);
    if (!child) continue;
    const double v = child->as_double();
    if (!(std::isfinite(v) && ((v > f.lo && v <= f.hi) || (f.zero_ok && v == 0.0))))
      child->fail("expected " + std::string(f.zero_ok ? (f.lo == 0.0 ? "a value in [" : "0 (off) or a value in (")
                                                      : "a value in (") +
                  core::number_for_message(f.lo) + ", " + core::number_for_message(f.hi) + "], got " + core::number_for_message(v));
    p.*f.v = v;
  }
  // The palm chord's settings (palm_breadth.hpp), in [0, 1].
  for (auto [key, v] : {std::pair{"palm_breadth_at", &p.palm_chord.at},
                        std::pair{"palm_breadth_min_facing", &p.palm_chord.min_facing}}) {
    const auto child = node.find(key);
    if (!child) continue;
    const double x = child->as_double();
    if (!(std::isfinite(x) && x >= 0.0 && x <= 1.0))
      child->fail("expected a value in [0, 1], got " + core::number_for_message(x));
    *v = x;
  }
  return p;
}

Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m) {
  return resized(m, length_m, width_m, m.shape.dimensions.thickness);
}

namespace {
/// The model `m` rebuilt with dimensions `d` (same side, coupling and limits).
Result<hand::HandModel> with_dimensions(const hand::HandModel& m, const hand::HandDimensions& d) {
  auto shape = hand::make_hand_shape(d);
  if (!shape) return shape.error();
  hand::HandModel out = m;
  out.shape = std::move(shape).value();
  return out;
}
}  // namespace

Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m,
                                double thickness) {
  hand::HandDimensions d = m.shape.dimensions;
  d.length = length_m;
  d.width = width_m;
  d.thickness = thickness;
  return with_dimensions(m, d);
}

namespace {
Eigen::Vector3d sizes_of(const hand::HandModel& m) {
  const hand::HandDimensions& d = m.shape.dimensions;
  return {d.length, d.width, d.thickness};
}
/// SplitMix64's finaliser: a well-mixed 64-bit hash of x.
std::uint64_t mix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Hand h's sizes at the shared estimate β (in hand 0's sizes): β ⊙ (start_h ⊘ start_0).
Eigen::Vector3d hand_sizes(const Eigen::Vector3d& beta, const std::vector<Eigen::Vector3d>& starts,
                           std::size_t h) {
  return beta.cwiseProduct(starts[h]).cwiseQuotient(starts[0]);
}
}  // namespace

ShapeEstimator::ShapeEstimator(const hand::HandModel& start, const ShapeEstimatorParams& params)
    : p_(params), models_{start}, starts_{sizes_of(start)}, candidates_(1, 0) {
  estimate_.length_m = starts_[0].x();
  estimate_.width_m = starts_[0].y();
  estimate_.thickness = starts_[0].z();
  estimate_.sigma_length_m = p_.prior_sigma_length_m;
  estimate_.sigma_width_m = p_.prior_sigma_width_m;
  estimate_.sigma_thickness = p_.prior_sigma_thickness;
  const Eigen::Vector3d sigma0(p_.prior_sigma_length_m, p_.prior_sigma_width_m, p_.prior_sigma_thickness);
  prior_H_ = sigma0.cwiseProduct(sigma0).cwiseInverse().asDiagonal();
  prior_h_ = prior_H_ * starts_[0];
  start_cap_reach_m_ = model_fingertip_reach_m(start);
  cap_reach_m_ = start_cap_reach_m_;
}

ShapeEstimator::ShapeEstimator(const std::array<hand::HandModel, 2>& starts,
                               const ShapeEstimatorParams& params)
    : ShapeEstimator(starts[0], params) {
  models_.push_back(starts[1]);
  starts_.push_back(sizes_of(starts[1]));
  candidates_.push_back(0);
}

ShapeEstimate ShapeEstimator::estimate(int hand) const {
  const auto h = static_cast<std::size_t>(hand);
  ShapeEstimate e = estimate_;
  if (h >= starts_.size()) return e;
  const Eigen::Vector3d scale = starts_[h].cwiseQuotient(starts_[0]);
  e.length_m *= scale.x();
  e.sigma_length_m *= scale.x();
  e.width_m *= scale.y();
  e.sigma_width_m *= scale.y();
  e.thickness *= scale.z();
  e.sigma_thickness *= scale.z();
  e.keyframes = static_cast<int>(std::count_if(keyframes_.begin(), keyframes_.end(),
                                               [&](const Keyframe& k) { return k.hand == hand; }));
  e.palm_chords = static_cast<int>(std::count_if(keyframes_.begin(), keyframes_.end(), [&](const Keyframe& k) {
    return k.hand == hand && k.chord.has_value();
  }));
  e.cap_reach_m = model_fingertip_reach_m(models_[h]);
  e.sigma_cap_reach_m = sigma_cap_reach_m_;
  e.cap_reach_samples = static_cast<int>(cap_reaches_.size());
  e.sections = static_cast<int>(section_sizes_.size());
  return e;
}

ShapeEstimator::Solve ShapeEstimator::run_solve(Solve job) {
  const ShapeEstimatorParams& p = job.params;
  const vision::Camera* camera = job.camera ? &*job.camera : nullptr;
  std::vector<hand::HandModel>& models = job.models;
  const std::vector<Eigen::Vector3d>& starts = job.starts;
  ShapeEstimate& estimate = job.estimate;
  ImageEvidence skeleton_only;  // fingertips, bracelet wrist and a prior: no matte (no joint-balls)
  skeleton_only.camera = camera;
  // The keyframes' silhouettes: each one's distance transform is made by the first re-estimate
  // that uses it and kept with the keyframe (apply() carries it back).
  bool any_silhouette = false;
  for (Keyframe& kf : job.keyframes) {
    if (kf.silhouette.empty()) continue;
    if (p.silhouette == ShapeSilhouette::kNone) continue;
    any_silhouette = true;
    if (kf.distance) continue;
    auto d = std::make_shared<vision::SilhouetteDistance>();
    if (!vision::silhouette_distance(kf.silhouette, d.get(), {.max_distance_px = kSilhouetteMarginPx, .downsample = 2}).ok())
      d->empty = true;
    kf.distance = std::move(d);
  }
  if (any_silhouette) {
    job.fit_params.silhouette_term = true;
    job.fit_params.silhouette_inward = true;
  }
  if (!p.digit_axes) job.fit_params.digit_axis_sigma_px = 0.0;
  // The keyframes' pose prior (toward each keyframe's last pose), widened by keyframe_prior_scale.
  job.fit_params.prior_sigma_wrist_m *= p.keyframe_prior_scale;
  job.fit_params.prior_sigma_rotation_rad *= p.keyframe_prior_scale;
  job.fit_params.prior_sigma_joint_rad *= p.keyframe_prior_scale;
  const RegistrationParams& fit_params = job.fit_params;
  const SuccessiveAdjustment solver(fit_params);
  // β = (length [m], width [m], thickness); the thickness only where silhouettes or sections are kept.
  // The digits' sections measure the capsules' radius (width × thickness): the thickness too.
  const int nb = any_silhouette || (p.digit_section_sigma > 0 && !job.section_sizes.empty()) ? 3 : 2;
  const Eigen::Vector3d beta0 = starts[0];
  // The prior, βᵀ H0 β − 2 h0ᵀ β: the starting profile's, and what left the window (accumulate).
  // Its mean (H0⁻¹ h0) makes its cost (β − mean)ᵀ H0 (β − mean) ≥ 0.
  const Eigen::Matrix3d H0 = job.prior_H;
  const Eigen::Vector3d prior_mean = H0.ldlt().solve(job.prior_h);
  const Eigen::Vector3d step_h(p.difference_step_m, p.difference_step_m,
                               p.difference_step_m / std::max(starts[0].y(), 1e-3));
  const double k = p.max_relative_change;
  const Eigen::Vector3d lo((1 - k) * beta0.x(), (1 - k) * beta0.y(), std::max(0.6, beta0.z() - 2 * k));
  const Eigen::Vector3d hi((1 + k) * beta0.x(), (1 + k) * beta0.y(), std::min(1.6, beta0.z() + 2 * k));
  // Hand h's model at β.
  auto model_at = [&](std::size_t h, const Eigen::Vector3d& b) {
    const Eigen::Vector3d d = hand_sizes(b, starts, h);
    return resized(models[h], d.x(), d.y(), d.z());
  };
  // Every hand's model at β into `models`; false (models unchanged) when β is not a valid size.
  auto set_models_at = [&](const Eigen::Vector3d& b) {
    std::vector<hand::HandModel> next;
    for (std::size_t h = 0; h < models.size(); ++h) {
      auto m = model_at(h, b);
      if (!m) return false;
      next.push_back(std::move(m).value());
    }
    models = std::move(next);
    return true;
  };
  const Eigen::Vector3d beta_start(estimate.length_m, estimate.width_m, estimate.thickness);
  Eigen::Vector3d beta = beta_start;
  // The sizes are taken only where the objective — Σ_k ‖r_k‖² at each keyframe's pose re-fitted
  // at those sizes, plus the sizes' prior — is the lowest visited: a Gauss-Newton step that
  // raises it (J_β is a linearisation, and the joint-balls' rows are left out of the width's
  // column) is halved back toward the best sizes instead of being followed. `iterations` steps
  // (or halvings), each evaluated: iterations + 1 evaluations.
  struct Best {
    double cost = std::numeric_limits<double>::infinity();
    Eigen::Vector3d beta;
    Eigen::Matrix3d H;
    std::vector<hand::HandParams> poses;  ///< the keyframes' re-fitted poses at beta
    std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> info;  ///< their S_k, g_k at beta
  } best;
  for (int it = 0; it <= p.iterations; ++it) {
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    double cost = (beta - prior_mean).dot(H0 * (beta - prior_mean));
    std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> info(job.keyframes.size());  // S_k, g_k
    for (std::size_t i = 0; i < job.keyframes.size(); ++i) {
      Keyframe& kf = job.keyframes[i];
      const auto hk = static_cast<std::size_t>(kf.hand);
      if (hk >= models.size()) continue;
      const hand::HandModel& model = models[hk];
      // The keyframe's pose at the current sizes (warm start, weak prior toward its last pose).
      ImageEvidence evidence = skeleton_only;
      if (!kf.owned.empty()) evidence.coverage = &kf.owned;
      if (kf.distance && !kf.distance->empty) evidence.distance = kf.distance.get();
      // The joint-balls read the 8-bit silhouette as the matte (0/255 sample as a 0/1 float copy
      // would): no float copy per keyframe, whose fresh megabyte was most of the demo's page faults.
      if (p.joint_balls) evidence.alpha = kf.silhouette;
      hand::HandParams prior = p.keyframe_prior == KeyframePrior::kTaken ? kf.q_taken : kf.q;
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
      std::vector<ResidualTerm> terms;
      stacked_residuals(problem, targets, kf.q, &r, &J, &terms);
      MatX Jb = MatX::Zero(r.size(), 3);
      // The palm's chord (palm_breadth.hpp): its model value at the keyframe's pose and sizes.
      const bool chord = kf.chord && camera != nullptr && p.palm_breadth_sigma_px > 0;
      auto chord_of = [&](const hand::HandModel& m) {
        return (model_palm_chord_px(m, kf.q, *camera, kf.chord->at, kf.chord->across_px) - kf.chord->measured_px) /
               p.palm_breadth_sigma_px;
      };
      const double r_chord = chord ? chord_of(model) : 0.0;
      Eigen::Vector3d J_chord = Eigen::Vector3d::Zero();
      bool ok = true;
      for (int c = 0; c < nb && ok; ++c) {
        VecX rp, rm;
        std::array<double, 2> chord_pm{};
        for (int sgn : {1, -1}) {
          Eigen::Vector3d b = beta;
          b[c] += sgn * step_h[c];
          auto m = model_at(hk, b);
          if (!m) {
            ok = false;
            break;
          }
          const hand::HandModel mm = std::move(m).value();
          const ResidualProblem pk{&mm, &kf.observation, &evidence, &prior, &fit_params};
          stacked_residuals(pk, targets, kf.q, sgn > 0 ? &rp : &rm, nullptr);
          if (chord) chord_pm[sgn > 0 ? 0 : 1] = chord_of(mm);
        }
        ok = ok && rp.size() == r.size() && rm.size() == r.size();
        if (ok) Jb.col(c) = (rp - rm) / (2.0 * step_h[c]);
        if (ok) J_chord[c] = (chord_pm[0] - chord_pm[1]) / (2.0 * step_h[c]);
      }
      // The joint-balls inform the length only: their targets sit a ball's radius in from the
      // silhouette's edge, and that radius is the capsule's, which the width scales. (The band's
      // length never enters: add_frame leaves it out of the keyframes.)
      if (ok)
        for (Eigen::Index row = 0; row < Jb.rows(); ++row)
          if (terms[static_cast<std::size_t>(row)] == ResidualTerm::kJointBall) Jb(row, 1) = 0.0;
      if (!ok || !J.allFinite() || !Jb.allFinite() || !r.allFinite()) continue;
      // Marginalise the pose (Schur complement).
      MatX A = J.transpose() * J;
      A.diagonal().array() += 1e-9 * std::max(1.0, A.diagonal().maxCoeff());
      const Eigen::LDLT<MatX> A_ldlt(A);
      const MatX JtJb = J.transpose() * Jb;
      const MatX JbtJ = JtJb.transpose();
      const Eigen::Matrix3d S_k = Jb.transpose() * Jb - JbtJ * A_ldlt.solve(JtJb);
      const Eigen::Vector3d g_k = -(Jb.transpose() * r - JbtJ * A_ldlt.solve(J.transpose() * r));
      S += S_k;
      g += g_k;
      info[i] = {S_k, g_k};
      cost += r.squaredNorm();
      // The chord's row: the pose is the keyframe's fit (its other evidence), held here.
      if (chord && std::isfinite(r_chord) && J_chord.allFinite()) {
        S += J_chord * J_chord.transpose();
        g -= J_chord * r_chord;
        cost += r_chord * r_chord;
      }
    }
    // The digits' sections pooled since the start (section_sizes): each a measurement of the
    // capsules' radius scale, log(β_width β_thickness / measured) / σ, whatever pose refits.
    if (p.digit_section_sigma > 0)
      for (const double m : job.section_sizes) {
        const double r_sec = std::log(beta.y() * beta.z() / m) / p.digit_section_sigma;
        const Eigen::Vector3d J_s = Eigen::Vector3d(0.0, 1.0 / beta.y(), 1.0 / beta.z()) / p.digit_section_sigma;
        S += J_s * J_s.transpose();
        g -= J_s * r_sec;
        cost += r_sec * r_sec;
      }
    if (it == 0) estimate.objective_start = cost;
    const bool better = cost < best.cost;
    if (!better) ++estimate.steps_rejected;
    if (better) {
      best.cost = cost;
      best.beta = beta;
      best.H = S + H0;
      best.poses.clear();
      for (const Keyframe& kf : job.keyframes) best.poses.push_back(kf.q);
      best.info = info;
    }
    if (it == p.iterations) break;  // the last step evaluated, not stepped from
    if (!better) {
      // Back toward the best sizes (their models are valid: every β visited was).
      beta = best.beta + 0.5 * (beta - best.beta);
      if (!set_models_at(beta)) break;
      continue;
    }
    const Eigen::Matrix3d& H = best.H;
    const Eigen::Vector3d rhs = g + H0 * (prior_mean - beta);
    // Solve over the sizes still free (frozen ones and, without silhouettes, the thickness stay).
    const std::array<bool, 3> free{!estimate.length_frozen, !estimate.width_frozen,
                                   nb == 3 && !estimate.thickness_frozen};
    std::vector<int> idx;
    for (int c = 0; c < 3; ++c)
      if (free[static_cast<std::size_t>(c)]) idx.push_back(c);
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    if (!idx.empty()) {
      const auto n = static_cast<Eigen::Index>(idx.size());
      Eigen::MatrixXd Hf(n, n);
      Eigen::VectorXd bf(n);
      for (Eigen::Index a = 0; a < n; ++a) {
        bf[a] = rhs[idx[static_cast<std::size_t>(a)]];
        for (Eigen::Index b = 0; b < n; ++b)
          Hf(a, b) = H(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]);
      }
      const Eigen::VectorXd sf = Hf.ldlt().solve(bf);
      for (Eigen::Index a = 0; a < n; ++a) step[idx[static_cast<std::size_t>(a)]] = sf[a];
    }
    if (!step.allFinite()) break;
    const Eigen::Vector3d next = (beta + step).cwiseMax(lo).cwiseMin(hi);
    if (!set_models_at(next)) break;  // outside the valid sizes: keep the last valid models
    beta = next;
    if (step.norm() < 1e-6) break;
  }
  ++estimate.solves;
  if (!std::isfinite(best.cost)) {  // no evaluation (no iterations): nothing changes
    job.changed = false;
    return job;
  }
  // The best sizes visited, with their models and the keyframes' poses fitted at them.
  if (best.beta != beta) (void)set_models_at(best.beta);  // valid: visited
  for (std::size_t i = 0; i < job.keyframes.size() && i < best.poses.size(); ++i) job.keyframes[i].q = best.poses[i];
  for (std::size_t i = 0; i < job.keyframes.size() && i < best.info.size(); ++i) {
    Keyframe& kf = job.keyframes[i];
    kf.S = best.info[i].first;
    kf.g = best.info[i].second;
    kf.beta_lin = best.beta;
  }
  beta = best.beta;
  estimate.objective = best.cost;
  const bool changed = (beta - beta_start).cwiseAbs().maxCoeff() > 1e-7;
  estimate.length_m = beta.x();
  estimate.width_m = beta.y();
  estimate.thickness = beta.z();
  const Eigen::Matrix3d cov = best.H.inverse();
  estimate.sigma_length_m = std::sqrt(std::max(cov(0, 0), 0.0));
  estimate.sigma_width_m = std::sqrt(std::max(cov(1, 1), 0.0));
  estimate.sigma_thickness = std::sqrt(std::max(cov(2, 2), 0.0));
  if (estimate.sigma_length_m < p.freeze_sigma_length_m) estimate.length_frozen = true;
  if (estimate.sigma_width_m < p.freeze_sigma_width_m) estimate.width_frozen = true;
  if (nb == 3 && estimate.sigma_thickness < p.freeze_sigma_thickness) estimate.thickness_frozen = true;
  job.changed = changed;
  return job;
}

ShapeEstimator::~ShapeEstimator() {
  if (pending_.valid()) pending_.wait();
}

bool ShapeEstimator::add_frame(int hand, const hand::HandParams& q, const HandObservation& observation,
                               const ImageEvidence& image, const RegistrationParams& fit_params) {
  if (hand < 0 || hand >= hands()) return false;
  if (estimate_.length_frozen && estimate_.width_frozen &&
      (estimate_.thickness_frozen || (p_.silhouette == ShapeSilhouette::kNone && p_.digit_section_sigma <= 0)))
    return false;
  if (!q.q.allFinite()) return false;
  int tips = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f)
    tips += observation.fingertip_valid[f] && observation.p_W_fingertip[f].allFinite() ? 1 : 0;
  if (tips < hand::kFingertipCount) return false;  // only fully measured hands make keyframes
  // With a camera the bracelet's wrist is part of a full measurement: without it nothing pins the
  // palm, four fingertips are reached by a longer or shorter hand alike, and a hand turned about
  // its fingertips (registration_study, the left hand at 7.0–7.3 s while its bracelet is hidden:
  // joints 14–15 px at a fingertip cost near 0) would pull the sizes wherever its pose needs.
  if (image.camera != nullptr &&
      !(observation.wrist_px && observation.wrist_px->allFinite() && observation.wrist_confidence > 0))
    return false;
  int held = 0;  // this hand's keyframes
  const Keyframe* oldest = nullptr;
  for (const Keyframe& k : keyframes_) {
    if (k.hand != hand) continue;
    if ((k.q.q - q.q).norm() < p_.min_pose_change) return false;  // nothing new
    ++held;
    if (oldest == nullptr || k.serial < oldest->serial) oldest = &k;
  }
  // Where it goes: a new slot, the oldest keyframe's, a random one's, or nowhere (KeyframeWindow).
  constexpr std::size_t kNowhere = std::numeric_limits<std::size_t>::max();
  std::size_t slot = keyframes_.size();
  const auto capacity = static_cast<std::uint64_t>(std::max(p_.keyframes, 1));
  const std::uint64_t n = ++candidates_.at(static_cast<std::size_t>(hand));  // this one's count
  if (static_cast<std::uint64_t>(held) >= capacity) {
    if (p_.keyframe_window == KeyframeWindow::kNewest) {
      slot = static_cast<std::size_t>(oldest - keyframes_.data());
    } else {
      const std::uint64_t j = mix64(n * 2 + static_cast<std::uint64_t>(hand)) % n;  // uniform in [0, n)
      slot = kNowhere;
      std::uint64_t seen = 0;
      for (std::size_t i = 0; i < keyframes_.size() && j < capacity; ++i)
        if (keyframes_[i].hand == hand && seen++ == j) slot = i;
    }
  }
  if (slot == kNowhere) {  // not kept; its image measures still count
    add_image_measures(hand, q, observation, image, fit_params);
    return update_cap_offset();
  }
  Keyframe kf{hand, next_serial_++, q, q, observation, {}, {}, {}, {}};
  // The band's length is left out of the size estimate's refits: with it the default user's width
  // went 18 % narrow (demo, seeds 1–2), without it 4–8 % (the band measures the forearm, whose
  // breadth the model only assumes in proportion to the palm's).
  kf.observation.wrist_length_px = 0.0;
  kf.observation.wrist_thickness_px = 0.0;
  if ((p_.silhouette != ShapeSilhouette::kNone || p_.joint_balls || p_.digit_section_sigma > 0) &&
      !image.alpha.empty() &&
      image.alpha.type() == CV_32FC1)
    cv::compare(image.alpha, fit_params.matte_threshold, kf.silhouette, cv::CMP_GE);
  if (p_.silhouette == ShapeSilhouette::kBoth && image.coverage != nullptr) kf.owned = *image.coverage;
  if (p_.palm_breadth_sigma_px > 0 && image.camera != nullptr && !image.alpha.empty() &&
      image.alpha.type() == CV_32FC1) {
    cv::Mat mask = kf.silhouette;
    if (mask.empty()) cv::compare(image.alpha, fit_params.matte_threshold, mask, cv::CMP_GE);
    kf.chord = measure_palm_chord(models_.at(static_cast<std::size_t>(hand)), q, *image.camera, mask,
                                  image.coverage, fit_params.coverage_stride_px, p_.palm_chord);
  }
  add_image_measures(hand, q, observation, image, fit_params);
  const bool cap_changed = update_cap_offset();
  if (slot == keyframes_.size()) {
    keyframes_.push_back(std::move(kf));
  } else {
    if (p_.accumulate) absorb(keyframes_[slot]);
    keyframes_[slot] = std::move(kf);
  }
  estimate_.keyframes = static_cast<int>(keyframes_.size());
  // solve_every counts a hand's keyframes: an estimate of both hands re-estimates over twice the
  // keyframes half as often, at the same cost per frame.
  if (++new_since_solve_ < p_.solve_every * hands() || estimate_.keyframes < p_.min_keyframes) return cap_changed;
  if (pending_.valid()) return cap_changed;  // one re-estimate at a time: the next frame's offer starts it
  new_since_solve_ = 0;
  Solve job = make_solve(image.camera, fit_params);
  if (p_.apply_after_frames <= 0) return apply(run_solve(std::move(job))) || cap_changed;
  polls_since_start_ = 0;
  pending_ = std::async(std::launch::async, [job = std::move(job)]() mutable {
    core::set_thread_name("spidar-shape");
    // An ordinary share below the frame thread's, whose scheduling (SCHED_FIFO in the session) it
    // inherited: a solve of 10–30 ms must not hold up the frames. Best effort.
    (void)core::apply_scheduling({SCHED_OTHER, 0, 0});
    return run_solve(std::move(job));
  });
  return cap_changed;
}

void ShapeEstimator::add_sections(int hand, const hand::HandParams& q, const vision::Camera& camera,
                                  const cv::Mat& alpha, double threshold) {
  const hand::HandModel& model = models_.at(static_cast<std::size_t>(hand));
  const hand::HandDimensions& d = model.shape.dimensions;
  const Eigen::Vector3d& start = starts_.at(static_cast<std::size_t>(hand));
  // The measured radius scale in β's units (hand 0's sizes): the model's width × thickness times
  // the section's real / model diameter, over the hand's width ratio to hand 0's.
  const double to_beta = starts_[0].y() / start.y();
  ProjectedHand outline;  // the hand's outline at q, for the sections' edges (digit_section_clear_edges)
  if (p_.digit_section_clear_edges) project_hand(model, q, camera, 0.0, &outline);
  for (const DigitAxisPoint& sec : digit_sections(model, q, camera, alpha, threshold)) {
    const BoneRef bone = silhouette_bone(sec.bone);
    if (bone.finger == hand::kThumb || bone.segment != 2) continue;  // the fingers' middle phalanges
    const double ratio = sec.width_px / sec.model_width_px;
    if (!(ratio > 1.0 / kSectionMaxRatio && ratio < kSectionMaxRatio)) continue;
    if (p_.digit_section_clear_edges && !(section_clearance_px(outline, sec) >= kSectionClearancePx)) continue;
    if (section_sizes_.size() >= kMaxSectionSizes) section_sizes_.erase(section_sizes_.begin());
    section_sizes_.push_back(d.width * d.thickness * ratio * to_beta);
  }
}

void ShapeEstimator::add_fingertip_ends(int hand, const hand::HandParams& q, const HandObservation& observation,
                                        const vision::Camera& camera, const cv::Mat& alpha, double threshold) {
  const hand::HandModel& model = models_.at(static_cast<std::size_t>(hand));
  ProjectedHand outline;  // an end inside another part of the fitted outline may be that part's edge
  project_hand(model, q, camera, 0.0, &outline);
  // Only reaches the offset may take count: a longer one has run on into something the outline
  // does not hold (the other hand).
  FingertipEndParams fe = p_.fingertip_end;
  fe.min_reach_m = std::max(fe.min_reach_m, start_cap_reach_m_ - p_.cap_offset_max_change_m);
  fe.max_reach_m = std::min(fe.max_reach_m, start_cap_reach_m_ + p_.cap_offset_max_change_m);
  for (const FingertipEnd& e : fingertip_ends(model, q, observation, camera, alpha, threshold, fe, &outline)) {
    if (cap_reaches_.size() >= kMaxCapReaches) cap_reaches_.erase(cap_reaches_.begin());
    cap_reaches_.push_back(e.reach_m);
  }
}

void ShapeEstimator::add_image_measures(int hand, const hand::HandParams& q, const HandObservation& observation,
                                        const ImageEvidence& image, const RegistrationParams& fit_params) {
  if (image.camera == nullptr || image.alpha.empty()) return;
  if (p_.digit_section_sigma > 0) add_sections(hand, q, *image.camera, image.alpha, fit_params.matte_threshold);
  if (p_.cap_offset_from_image)
    add_fingertip_ends(hand, q, observation, *image.camera, image.alpha, fit_params.matte_threshold);
}

bool ShapeEstimator::set_cap_reach(std::vector<hand::HandModel>* models, double reach_m) {
  std::vector<hand::HandModel> next;
  for (const hand::HandModel& m : *models) {
    hand::HandDimensions d = m.shape.dimensions;
    d.fingertip_offset.y() = -reach_m;
    auto with = with_dimensions(m, d);
    if (!with) return false;
    next.push_back(std::move(with).value());
  }
  *models = std::move(next);
  return true;
}

bool ShapeEstimator::update_cap_offset() {
  const auto n = cap_reaches_.size();
  if (!p_.cap_offset_from_image || n == 0) return false;
  // The pool's median, and its σ from the median absolute deviation (robust to the ends that
  // the checks let through on another finger's outline).
  std::vector<double> v = cap_reaches_;
  auto median = [](std::vector<double>* x) {
    const auto mid = x->begin() + static_cast<std::ptrdiff_t>(x->size() / 2);
    std::nth_element(x->begin(), mid, x->end());
    return *mid;
  };
  const double med = median(&v);
  for (double& x : v) x = std::abs(x - med);
  sigma_cap_reach_m_ = 1.2533 * 1.4826 * median(&v) / std::sqrt(static_cast<double>(n));
  if (static_cast<int>(n) < p_.cap_offset_min_samples) return false;
  const double k = p_.cap_offset_max_change_m;
  const double reach = std::clamp(med, start_cap_reach_m_ - k, start_cap_reach_m_ + k);
  if (std::abs(reach - cap_reach_m_) < kCapReachStepM) return false;
  if (!set_cap_reach(&models_, reach)) return false;
  cap_reach_m_ = reach;
  return true;
}

void ShapeEstimator::absorb(const Keyframe& k) {
  // Never in a re-estimate (S = 0), or skipped there: nothing known to keep. A size not estimated
  // (the thickness without sections) has zero rows; a frozen one's information is kept, and no
  // step moves it.
  if (!(k.S.allFinite() && k.g.allFinite() && k.beta_lin.allFinite() && k.S.trace() > 0)) return;
  prior_H_ += k.S;
  prior_h_ += k.S * k.beta_lin + k.g;
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
  job.models = models_;
  job.starts = starts_;
  job.keyframes = keyframes_;
  job.section_sizes = section_sizes_;
  job.prior_H = prior_H_;
  job.prior_h = prior_h_;
  job.estimate = estimate_;
  return job;
}

bool ShapeEstimator::apply(Solve&& done) {
  models_ = std::move(done.models);
  // A cap offset set while the re-estimate ran (its models carry the one it started with).
  bool cap_changed = false;
  if (!models_.empty() && std::abs(model_fingertip_reach_m(models_[0]) - cap_reach_m_) > 1e-12)
    cap_changed = set_cap_reach(&models_, cap_reach_m_);
  const int keyframes = estimate_.keyframes;
  estimate_ = done.estimate;
  estimate_.keyframes = keyframes;
  // The keyframes' refitted poses warm-start the next re-estimate, unless keyframes came since it
  // started (new_since_solve_ counts them from its start).
  if (new_since_solve_ == 0) {
    keyframes_ = std::move(done.keyframes);
  } else {  // the distance transforms it made, and their information, stay with the keyframes still held
    for (Keyframe& k : keyframes_)
      for (const Keyframe& d : done.keyframes)
        if (d.serial == k.serial) {
          if (!k.distance) k.distance = d.distance;
          k.S = d.S;
          k.g = d.g;
          k.beta_lin = d.beta_lin;
        }
  }
  return done.changed || cap_changed;
}

}  // namespace spidar::registration
