#pragma once
/// Online hand-shape personalisation: each hand's length and width [m] estimated while the
/// session runs, from the evidence the pose fits already use, with no calibration step.
///
/// After each frame's pose fit θ, the residuals the shape should explain (the string-measured
/// fingertips in 3D and the bracelet's projected wrist, residuals.hpp, with the temporal prior on
/// θ) are linearised in both the pose θ (17) and the shape β = (length, width):
///   r(θ + Δθ, β + Δβ) ≈ r + J_θ Δθ + J_β Δβ      (J_β by central differences of the model)
/// and the pose is marginalised out (Schur complement), giving this frame's information on β
/// alone:  S = J_βᵀJ_β − J_βᵀJ_θ (J_θᵀJ_θ)⁻¹ J_θᵀJ_β,  g = −(J_βᵀr − J_βᵀJ_θ (J_θᵀJ_θ)⁻¹ J_θᵀr).
/// The evidence accumulates in information form, as a Kalman filter on a constant parameter
/// (Tkach et al. 2017, "Online generative model personalization for hand tracking"):
///   H ← λ H + w S,   β ← β + H⁻¹ w g   (λ ≤ 1 forgets old, badly linearised evidence),
/// starting from the given profile with its prior σ. Consecutive frames repeat much of the same
/// evidence, so each frame counts with weight w < 1, and only frames whose pose moved since the
/// last used one are used (several poses make the shape observable; one pose does not separate
/// a longer finger from a more flexed one). A parameter whose σ = √(H⁻¹)ᵢᵢ falls below its
/// freeze threshold is frozen: later frames no longer move it (Monado's hand-size schedule does
/// the same with a time budget).
///
/// The image's joint-ball and silhouette terms are left out on purpose: they compare the model's
/// capsules and skin with a real hand's outline, whose systematic differences (knuckles, pads,
/// tissue) would bias the sizes; the strings and the bracelet measure points of the skeleton.

#include <array>

#include "spidar/core/config.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/successive_adjustment.hpp"

namespace spidar::registration {

struct ShapeEstimatorParams {
  double prior_sigma_length_m = 0.015;  ///< σ of the starting profile's length [m]
  double prior_sigma_width_m = 0.008;   ///< σ of its width [m]
  /// The accumulated information decays by this factor per used frame (1 = never forget).
  /// Measured (tests/registration/test_shape_estimator.cpp): without forgetting a small hand's
  /// length locks in short of the truth (0.1855 m for 0.171 m); with 0.97 the estimates wander
  /// (±5 mm). Neither is good enough yet; 1 is the default.
  double forgetting = 1.0;
  double frame_weight = 0.3;            ///< w: how much one frame counts (0, 1]
  double min_pose_change = 0.02;        ///< use a frame once θ moved this much (norm, m/rad)
  double freeze_sigma_length_m = 0.0005;  ///< freeze the length once its σ is below this [m]
  double freeze_sigma_width_m = 0.0005;   ///< ... the width [m]
  double max_step_m = 0.002;            ///< largest change of either size per frame [m]
  /// The estimate stays within this share of the starting sizes (0.15: ±15 %). Width and finger
  /// abduction trade off in the strings' evidence; without a bound, a poorly observed width can
  /// run away (seen on the simulated rig: 0.0935 m estimated as 0.054 m).
  double max_relative_change = 0.15;
  double difference_step_m = 1e-4;      ///< central-difference step of J_β [m]
};

/// The estimate of one hand.
struct ShapeEstimate {
  double length_m = 0;
  double width_m = 0;
  double sigma_length_m = 0;  ///< √(H⁻¹) [m]
  double sigma_width_m = 0;
  bool length_frozen = false;
  bool width_frozen = false;
  int frames_used = 0;
};

class ShapeEstimator {
 public:
  /// Starts from `start` (its length and width; sides, coupling and limits are kept).
  ShapeEstimator(const hand::HandModel& start, const ShapeEstimatorParams& params = {});
  /// Adds one frame's evidence: `q` the pose fitted with model(), `observation` and `image` what
  /// the fit used (only the camera of `image` is used), `prior` the fit's temporal prior (may be
  /// null). Returns true when the sizes changed (model() was rebuilt).
  bool add_frame(const hand::HandParams& q, const HandObservation& observation,
                 const ImageEvidence& image, const hand::HandParams* prior,
                 const RegistrationParams& fit_params);
  const hand::HandModel& model() const { return model_; }
  const ShapeEstimate& estimate() const { return estimate_; }

 private:
  ShapeEstimatorParams p_;
  hand::HandModel model_;
  Eigen::Matrix2d H_ = Eigen::Matrix2d::Zero();
  hand::HandParams last_used_;
  bool have_last_ = false;
  ShapeEstimate estimate_;
  double start_length_m_ = 0, start_width_m_ = 0;
};

/// Reads a `personalisation:` map (every key optional): enabled (bool, into `*enabled`),
/// prior_sigma_length_m, prior_sigma_width_m, frame_weight, min_pose_change,
/// freeze_sigma_length_m, freeze_sigma_width_m, max_step_m, max_relative_change. Throws core::ConfigError naming
/// file:line: key and the expected range.
ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled);

/// The model `m` with other sizes (same side, coupling and limits). Fails on invalid sizes.
Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m);

}  // namespace spidar::registration
