#pragma once
/// Settings of the successive adjustment (registration/successive_adjustment.hpp).
///
/// Units on one scale: every residual is divided by its standard deviation σ, so the cost
///   J = Σ (fingertip error / σ_tip)² + conf · (wrist error / σ_wrist)² + Σ (joint-ball error / σ_ball)²
///       [+ Σ (silhouette error / σ_sil)²] + Σ ((θ − θ_prev) / σ_prior)²
///       [+ Σ ((θ_little − θ_ring) / σ_little)², with little_free]
/// is dimensionless. The paper's J = ‖ΔQ‖² + c‖ΔP‖² (eq. 22) is the special case
/// c = σ_tip² / σ_ball² with ΔQ's wrist entry weighted by σ_tip / σ_wrist [m/px].
///
/// configs/registration.yaml holds the same values with their units; every key is optional.
#include "spidar/core/config.hpp"
#include "spidar/core/result.hpp"

namespace spidar::registration {

struct RegistrationParams {
  // --- terms ---
  double fingertip_sigma_m = 0.0015;  ///< σ of a string-measured fingertip [m]
  double wrist_sigma_px = 4.0;        ///< σ of the bracelet's projected wrist [px]
  /// Where the bracelet sits: its centre lies this far from the wrist joint toward the elbow
  /// (along −y of the hand frame) [m]; the wrist term compares the projection of that point with
  /// the bracelet's midpoint. 0 = the paper's "the bracelet marks the wrist".
  double bracelet_offset_m = 0.012;
  /// The camera sees the near half of the band, so the bracelet's detected midpoint is not its
  /// centre on the forearm's axis but lies toward the camera, on the band's visible surface: the
  /// wrist term compares it with the band centre shifted by surface_shift × r toward the camera
  /// (across the forearm), r = radius_per_width × hand width + standoff. 0 = the band centre
  /// itself (the paper's "the bracelet marks the wrist"). Measured on the simulated rig over the
  /// demo's script (tests/pipeline/registration_study): the detected midpoint lies 10.5 px from
  /// the centre's projection, 3.8–3.9 px from the shifted point's at 0.4–0.6 r (2/π ≈ 0.64 would
  /// be a uniformly seen half ring's centroid; the detector takes the middle of the band's extent).
  double bracelet_surface_shift = 0.5;
  /// The wrist term's expected midpoint from the detector's own rule instead of the shift above:
  /// the band's near side projected (an ellipse section, bracelet_midpoint_px), the middle of its
  /// extent along its major axis, its area's centroid across it, as vision/bracelet.cpp takes them
  /// from the red pixels. With the simulated users' bending wrists (registration_study, default
  /// user, true sizes, at the true pose): 3.8 px from the detected midpoint (p95 6.3), against
  /// 6.5–7.0 px for the best constant shift (0.4–0.6 r) along the true forearm. Off: in the demo
  /// (seeds 1–2) the fitted wrists came nearer the true ones in the image (5.8 / 5.6 → 4.3 / 4.2 px)
  /// and the left palm's roll bias fell (+4.5 → +1.3°), but the palms' spill rose and the IoU fell
  /// (0.872 / 0.873 → 0.863 / 0.870; docs/measurements.md, session 43).
  bool bracelet_detector_midpoint = false;
  double bracelet_radius_per_width = 0.31;  ///< forearm radius at the band / palm width
  double bracelet_standoff_m = 0.002;        ///< how far the band stands off the skin [m]
  /// The forearm at the band is an ellipse, not a circle: its depth (back of the wrist to its
  /// palmar side) over its breadth (bracelet_radius_per_width is the half breadth). Adult wrists
  /// are about 0.6–0.7 as deep as broad (anthropometric surveys: breadth ≈ 5.5–6.5 cm, depth ≈
  /// 3.5–4.5 cm). The band's projected length depends on which side the camera sees.
  double bracelet_depth_ratio = 0.65;
  /// σ of the band's length across the forearm in the image, relative to the detected length
  /// (the bracelet term's second part, residuals.hpp): the band's apparent size says how far the
  /// wrist is along its ray, which the projected midpoint cannot (a hand turned about its
  /// fingertips can put its wrist on that ray at two depths). Covers the user's wrist differing
  /// from the model's proportions. 0 = not used (the paper's midpoint only), the default:
  ///
  /// Measured (demo, 2026-11-26): on scenes/blocks.xml the left wrist, after its band was hidden
  /// for 1.5 s, came back on the band's ray 55–70 mm too deep and turned 22–29° (the silhouette
  /// fits either depth as well), in 3 of 6 seeds: the contested pixels 14–15 % wrong there, 2.5–
  /// 3.6 % otherwise. At 0.06 all 6 seeds stayed right (1.6–3.2 %), at 0.12 one of 6 did not. But
  /// the band's predicted size scales with the estimated hand width: the large user (width 10 %
  /// above the model's, estimated 9–23 % off) then got wrists pulled toward the camera, the
  /// contested pixels 9.2–10.4 % wrong against 1.4–1.7 % without (rubiks, seeds 1–2). Not the
  /// default until the width is estimated well (or the band's size with it).
  double bracelet_length_sigma = 0.0;
  /// No band cost while the predicted length is within this share of the detected one (the
  /// user's forearm is not the model's; the band tells the two depths of a ray apart, it does
  /// not measure the depth finely).
  double bracelet_length_tolerance = 0.1;
  /// The band's length is used only where both its ends lie inside the image and its pixels fill
  /// at least this share of its oriented box (a band partly hidden or cut looks short, i.e. far;
  /// its confidence is no guide: it is judged against the length the last fit predicts, and a
  /// band merely touching the image border along its side is scaled down to 0.3).
  double bracelet_length_min_fill = 0.6;
  /// ... and only where it is within this share of the length the previous fit predicts (a band
  /// merged with the other hand's, or the other hand's band taken for this one, would otherwise
  /// pull the wrist toward the camera; a wrist at the wrong one of the two depths its ray allows
  /// predicts a band about 20–35 % shorter, which the gate still lets through).
  double bracelet_length_gate = 0.4;
  /// The band's width along the forearm [m] (the bracelet's own, measured once), for its thickness.
  double bracelet_width_m = 0.018;
  /// σ of the band's thickness in the image (its extent along the forearm: the band's width and
  /// its near rim, foreshortened by how obliquely the camera sees the forearm), relative to the
  /// detected thickness beyond bracelet_thickness_tolerance; 0 = not used. The band's length
  /// cannot tell the two depths of a wrist's ray apart where the user's forearm is not the
  /// model's; the thickness can: the hand turned 20–30° about its fingertips that puts the wrist
  /// at the deeper one sees the band 25–30 % thinner (registration study, 2026-11-26).
  /// Used under the band length's conditions (a solid band, ends inside the image, the gate).
  double bracelet_thickness_sigma = 0.0;
  double bracelet_thickness_tolerance = 0.15;  ///< no cost within this share of the detected thickness
  /// σ of a joint-ball target [px]. The targets come from the silhouette around each model joint
  /// (eq. 21) and are only as good as its neighbourhood: 8 rather than 4 lets the fingertips and
  /// the silhouette term hold the joints where the balls disagree (docs/measurements.md, "The
  /// joint-balls' σ").
  double joint_ball_sigma_px = 8.0;
  double joint_ball_alpha = 0.5;      ///< α of eq. 21 (dimensionless, 0..1)
  double ball_radius_scale = 1.0;     ///< ball radius = scale × the bone's projected radius
  double matte_threshold = 0.5;       ///< a neighbour is "on the silhouette" if alpha ≥ this
  /// The hand-aware silhouette term (coverage.hpp): silhouette pixels a hand owns and its model
  /// leaves uncovered pull the model. Off: the paper's method (joint-balls alone).
  bool silhouette_term = false;
  /// With silhouette_term, also the inward direction: model points lying outside the real
  /// silhouette are pulled onto their nearest silhouette pixel (needs ImageEvidence::distance, a
  /// distance transform). Off by default: on the simulated rig it did not raise IoU and costs
  /// 1–2 ms per frame (tests/pipeline/registration_study, issue 14's note).
  bool silhouette_inward = false;
  double silhouette_sigma_px = 40.0;  ///< σ of an inward sample's distance [px]
  int silhouette_samples_per_bone = 3;  ///< inward samples along each bone (each gives 3 points), 1..8
  /// The silhouette term's coverage direction (coverage.hpp): silhouette pixels this hand owns
  /// that no part of its model covers pull the nearest part's edge toward them. σ of that
  /// distance [px] (> 0).
  double coverage_sigma_px = 50.0;
  int coverage_stride_px = 6;       ///< the silhouette is sampled on a grid this coarse [px], 1..64
  /// A pixel farther than this from every part of its owning hand is not this hand's evidence
  /// (a forearm, a bracelet, the other hand's fingers at a wrong prediction) [px].
  double coverage_max_px = 30.0;
  /// Uncovered pixels farther than this from the model count with a Huber weight (huber / d):
  /// far pixels are as likely a shape the model lacks as a pose error [px].
  double coverage_huber_px = 10.0;
  /// The digits' axes in the image (with silhouette_term: part of the hand-aware image terms, not
  /// the paper's): across each phalanx, at two points along it, the matte is
  /// walked out both ways from the model's projected axis to the silhouette's edges, and the axis
  /// pulled onto the edges' midpoint (one row each, across the bone) with this σ [px]; 0 = off.
  /// The midpoint of a finger's two edges is its axis whatever its thickness: unlike the
  /// joint-balls (whose neighbours sit at the model's radius) and the coverage (which pulls a
  /// capsule's edge onto tissue it lacks), a finger thicker or thinner than the model's capsule
  /// does not bias it. A cross-section whose width is not within [0.5, 1.8] times the model's
  /// diameter (fingers side by side, a finger crossing another, a bone seen end-on) is left out,
  /// and so is a midpoint more than the model's radius from its axis (another finger's, most
  /// likely). Not used from a cold start (the pipeline's first frame and restarts).
  ///
  /// Measured (2026-11-27, docs/measurements.md "The digits' axes"): in the registration study
  /// with the true sizes, σ 5 lowered the joint error for four users of five (mean 5.22 → 4.93
  /// px) at the same or better IoU; in the demo (18 runs per setting, five users and the blocks
  /// scene) it left the IoU where it was (mean 0.826 either way), the joints 7.54 → 7.07 px, but
  /// the blocks scene and the short, wide user lost IoU and contested pixels, and the outcome
  /// swung with the size estimate: not the default.
  double digit_axis_sigma_px = 0.0;
  /// The little finger's own parameters (hand/parameters.hpp, 17..19): free (the default), the
  /// little finger moves on its own, observed by the image terms alone (no string measures it), held near the
  /// ring finger's angles by a coupling prior of σ little_coupling_sigma_rad per angle. Off: the
  /// paper's little finger, which copies the ring finger. Only with silhouette_term
  /// (little_moves_freely): the paper's method keeps the paper's little finger.
  bool little_free = true;
  double little_coupling_sigma_rad = 0.25;  ///< σ of (little − ring) per angle [rad]
  /// The forearms' direction from their bands (registration/forearm_from_band.hpp): each frame,
  /// the bend within forearm_max_bend_rad of the hand's axis whose band best explains the detected
  /// band's thickness and long axis, for the bracelet term and the forearm's outline (the paper's
  /// forearm is in line with the hand). Only with silhouette_term (forearms_from_bands): the
  /// paper's method keeps the paper's forearm. Measured 2026-11-28 (docs/measurements.md, "The
  /// forearm's direction"): with bending wrists, registration study, five users, IoU +0.02..0.10
  /// over the in-line forearm, within 0.01 of the true forearm given; the crescent's bulge
  /// (forearm_bulge_sigma) tells a tilt toward the camera from one away. With a simulated forearm
  /// that stays in line (the paper's model's), the demo's IoU is 0.007 lower with it than without.
  bool forearm_from_band = true;
  double forearm_max_bend_rad = 1.2;        ///< the wrist's bend, at most (a cone) [rad], (0, π/2]
  double forearm_thickness_sigma = 0.3;     ///< σ of the band's thickness, predicted / detected − 1
  double forearm_axis_sigma_rad = 0.05;     ///< σ of the band's long axis's angle [rad]
  double forearm_bend_sigma_rad = 0.8;      ///< σ of the prior toward the in-line forearm [rad]
  double forearm_previous_sigma_rad = 0.3;  ///< σ of the prior toward the last estimate [rad]
  /// σ of the band's bulge (vision::BraceletObservation::bulge_px) as a share of its thickness,
  /// predicted − detected: the crescent's side, which tells a tilt toward the camera from one away.
  double forearm_bulge_sigma = 0.1;
  // --- temporal prior (toward the previous frame's parameters) ---
  double prior_sigma_wrist_m = 0.02;     ///< [m]
  double prior_sigma_rotation_rad = 0.2; ///< [rad]
  double prior_sigma_joint_rad = 0.3;    ///< [rad]
  // --- solver ---
  double lambda_initial = 1e-3;  ///< Levenberg-Marquardt damping, relative to diag(A)
  int max_iterations = 10;       ///< linear solves per fit, accepted or rejected (1..1000)
  double cost_epsilon = 1e-3;    ///< stop when J < ε (dimensionless)
  double step_epsilon = 1e-6;    ///< stop when ‖Δθ‖ < this (mixed m/rad)
  /// Stop when an accepted step lowers J by less than this share of J (noisy data never reaches
  /// cost_epsilon; this ends the fit once it no longer pays). 0 = off.
  double relative_epsilon = 1e-3;
};

/// Whether a fit's little finger moves on its own: little_free with the silhouette term (the
/// image is all that observes it). The paper's method (no silhouette term) always copies the ring.
inline bool little_moves_freely(const RegistrationParams& p) { return p.little_free && p.silhouette_term; }

/// Whether the forearms' direction is estimated from their bands: forearm_from_band with the
/// silhouette term. The paper's method keeps its forearm in line with the hand.
inline bool forearms_from_bands(const RegistrationParams& p) { return p.forearm_from_band && p.silhouette_term; }

/// Upper bound of silhouette_samples_per_bone (fixed-size storage, no allocation per frame).
inline constexpr int kMaxSilhouetteSamplesPerBone = 8;

/// Error naming the bad field and what was expected (all σ > 0, α in [0, 1], ...).
Status validate(const RegistrationParams& params);

/// Reads a `registration:` map (every key optional, defaults above). Throws core::ConfigError
/// naming file:line: key.
RegistrationParams parse_registration_params(const core::ConfigNode& node);

}  // namespace spidar::registration
