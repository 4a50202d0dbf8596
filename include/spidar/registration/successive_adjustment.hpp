#pragma once
/// Successive adjustment of the 17-parameter hand (paper, eqs 22–39) with the improvements a
/// real-time tracker needs: Levenberg-Marquardt damping, joint limits, a temporal prior, an
/// optional silhouette term and, with it, optionally a little finger of its own (3 more
/// parameters, RegistrationParams::little_free).
///
/// Each iteration linearises every residual r(θ + Δθ) ≈ r(θ) + J Δθ (fingertips from the strings
/// in 3D, the projected wrist from the bracelet, the joint-ball targets of eq. 21 recomputed at
/// the current pose, silhouette samples, the prior) and solves
///   (A + λ diag(A)) Δθ = b,   A = Σ JᵀJ,  b = −Σ Jᵀ r    (eq. 39's Δθ = A⁺ b when λ = 0)
/// with the residuals divided by their σ (registration_params.hpp), then clamps θ + Δθ into the
/// joint limits. A step that does not lower the cost (evaluated with the image targets frozen at
/// the linearisation, residuals.hpp) is rejected and λ grows ×10; an accepted step shrinks it ÷10.
/// Every solve, accepted or rejected, counts as one iteration. It stops when J < cost_epsilon,
/// ‖Δθ‖ < step_epsilon, an accepted step gains less than relative_epsilon·J, or after
/// max_iterations.
///
/// Details beyond the paper (residuals.hpp has the exact residuals):
///  - the wrist term compares the bracelet's midpoint with the projection of the point
///    bracelet_offset_m from the wrist joint toward the elbow (0 = joint 0 itself);
///  - joint-balls sit at MCP, PIP and DIP of every finger (little included) and at the thumb's
///    CMC, MCP and IP; not at the wrist nor the tips (joint_balls.cpp says why). A ball enters the
///    cost only where eq. 21 moves its joint (P̃ ≠ P): one wholly inside the silhouette would add
///    only a spring holding the joint at the current iterate, slowing convergence several-fold;
///  - the silhouette term (coverage.hpp) pulls the nearest part of the model toward each silhouette
///    pixel this hand owns and leaves uncovered (> 0.5 px; ImageEvidence::coverage, the owners
///    decided per frame among both hands and forearms); with silhouette_inward also model points
///    lying outside the real silhouette onto their nearest silhouette pixel (a distance transform),
///    and with digit_axis_sigma_px each phalanx's projected axis onto the midpoint of the
///    silhouette's two edges across it.
/// Nothing here allocates per frame.
#include <array>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/joint_balls.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/silhouette.hpp"

namespace spidar::registration {

struct OwnedPixel;  // coverage.hpp

/// What is measured of one hand in one frame.
struct HandObservation {
  std::array<Vec3, hand::kFingertipCount> p_W_fingertip = zeros<Vec3, hand::kFingertipCount>();  ///< from the strings, world [m]
  std::array<bool, hand::kFingertipCount> fingertip_valid{};
  std::optional<Vec2> wrist_px;  ///< projected wrist from the bracelet [px]
  double wrist_confidence = 1.0; ///< 0..1, multiplies the wrist term's weight
  /// The band's length across the forearm in the image (vision::BraceletObservation::length_px)
  /// [px], where the detection is whole enough to be measured; 0 = not measured.
  double wrist_length_px = 0.0;
  /// The band's thickness (vision::BraceletObservation::thickness_px: its extent across its long
  /// axis) [px] and that long axis in the image (unit), under the same conditions; 0 = not measured.
  double wrist_thickness_px = 0.0;
  Vec2 wrist_axis_px = Vec2::Zero();
  /// The forearm's direction from the wrist toward the elbow, in right-hand H coordinates (unit):
  /// the bracelet sits bracelet_offset_m along it. (0, −1, 0) is the forearm in line with the
  /// hand (the paper's assumption); a bent wrist turns it (given to the pipeline by
  /// FramePipeline::set_forearm_directions, or estimated by registration/forearm_from_band.hpp).
  Vec3 forearm_H = Vec3(0.0, -1.0, 0.0);
};

/// The image evidence shared by both hands. Without a camera only the 3D terms and the prior act.
struct ImageEvidence {
  const vision::Camera* camera = nullptr;
  /// The chroma-key matte for the joint-balls: CV_32FC1 in [0, 1] (1 = hand), or a CV_8UC1
  /// silhouette (255 = hand, as vision::sample_bilinear reads it); empty = no joint-balls.
  cv::Mat alpha;
  const vision::SilhouetteDistance* distance = nullptr;  ///< silhouette term; null = off
  /// The silhouette pixels this hand owns (coverage.hpp's coverage_evidence) for the silhouette
  /// term's coverage direction; null = that direction is off. Per hand.
  const std::vector<OwnedPixel>* coverage = nullptr;
};

/// Cost of each term at the final pose (dimensionless, see registration_params.hpp).
struct TermCosts {
  double fingertip = 0, wrist = 0, joint_ball = 0, silhouette = 0, prior = 0;
  double total() const { return fingertip + wrist + joint_ball + silhouette + prior; }
  /// The evidence's share, without the prior: what compares fits started from different poses
  /// (each prior holds the basin its own start is in).
  double evidence() const { return total() - prior; }
};

struct FitReport {
  int iterations = 0;
  double cost_initial = 0;
  double cost_final = 0;
  TermCosts terms;
  bool converged = false;  ///< stopped by ε (cost or step), not by max_iterations
};

class SuccessiveAdjustment {
 public:
  /// Throws SpidarError (naming the field) if the params are invalid.
  explicit SuccessiveAdjustment(const RegistrationParams& params = {});
  const RegistrationParams& params() const { return params_; }

  /// Fits one hand. `params` holds the start (the previous frame's result: warm start) on entry
  /// and the fit on return; `prior` is the temporal prior's mean (usually the same previous
  /// result; null = no prior). Never produces NaN: non-finite observations (fingertips, wrist
  /// pixel, confidence, prior entries) are ignored, a NaN start is clamped to finite values, and
  /// a matte that is not CV_32FC1 counts as no matte. The report's cost_final and terms are at
  /// the final pose with the image targets recomputed there. The result's little_independent is
  /// little_moves_freely(params()); a start whose little finger copied the ring starts its own
  /// little finger at the ring's angles.
  FitReport fit(const hand::HandModel& model, const HandObservation& observation,
                const ImageEvidence& image, const hand::HandParams* prior,
                hand::HandParams* params) const;

 private:
  RegistrationParams params_;
};

}  // namespace spidar::registration
