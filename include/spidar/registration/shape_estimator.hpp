#pragma once
/// Online hand-shape personalisation: each hand's length and width [m], and with the silhouette
/// its digits' thickness (hand_shape.hpp's HandDimensions::thickness), estimated while the
/// session runs, from the evidence the pose fits already use, with no calibration step.
///
/// The estimator keeps a small set of keyframes: frames whose pose differs from every kept one
/// (one pose does not separate a longer finger from a more flexed one; several do), each with its
/// observation (the string-measured fingertips in 3D and the bracelet's projected wrist) and its
/// pose. Every `solve_every` used frames it re-estimates the shape β = (length, width, thickness) over all
/// keyframes, as in the batch step of Tkach et al. 2017 ("Online generative model personalization
/// for hand tracking"), by Gauss-Newton on
///   Σ_k ‖r_k(θ_k, β)‖² + ‖β − β₀‖²_{Σ₀⁻¹}
/// with each keyframe's pose θ_k re-fitted at the current β (so no evidence stays linearised at an
/// old, wrong size) and marginalised out (Schur complement): with J_θ, J_β the Jacobians of r_k
/// (J_β by central differences of the model),
///   S_k = J_βᵀJ_β − J_βᵀJ_θ (J_θᵀJ_θ)⁻¹ J_θᵀJ_β,   g_k = −(J_βᵀ − J_βᵀJ_θ (J_θᵀJ_θ)⁻¹ J_θᵀ) r_k,
///   (Σ S_k + Σ₀⁻¹) Δβ = Σ g_k + Σ₀⁻¹ (β₀ − β).
/// A step that raises the objective (J_β is a linearisation) is halved back, never followed.
/// σ = √diag((Σ S_k + Σ₀⁻¹)⁻¹) is the estimate's uncertainty; a size whose σ falls below its
/// freeze threshold is frozen (Monado's hand-size schedule likewise stops adapting once sure).
/// With ShapeEstimatorParams::accumulate (the default) the prior also holds what the keyframes
/// that left the window knew (their S_k and g_k at their last re-estimate): Σ₀⁻¹ and β₀ become
/// the session's information H_p and its mean H_p⁻¹ h_p, so the estimate and its σ are the whole
/// session's, not the window's.
///
/// Without the silhouette (ShapeEstimatorParams::silhouette kNone) the evidence is the strings and
/// the bracelet, which measure points of the skeleton: a model longer than the hand then bends
/// its fingers to reach the caps, so a too-long estimate is hardly corrected, and the width and
/// thickness are weakly seen. With it, each keyframe also keeps its silhouette: model points
/// outside the silhouette (kSpill), and the silhouette pixels the hand owns that the model leaves
/// uncovered (kBoth, coverage.hpp), enter the re-estimate, and the digits' thickness is estimated
/// too. A silhouette point's offset from its bone's axis scales with the capsule's radius
/// (SilhouettePoint::radius_m), so the image rows do see the width and thickness. The joint-balls
/// enter only with ShapeEstimatorParams::joint_balls.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <future>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/registration/fingertip_end.hpp"
#include "spidar/registration/palm_breadth.hpp"
#include "spidar/registration/successive_adjustment.hpp"

namespace spidar::vision {
struct SilhouetteDistance;
}  // namespace spidar::vision

namespace spidar::registration {

/// Which of the keyframes' silhouette evidence a re-estimate fits (see the file comment).
enum class ShapeSilhouette {
  kNone,   ///< strings and bracelet only; the thickness stays
  kSpill,  ///< also model points lying outside the silhouette (the silhouette term's inward direction)
  kBoth,   ///< also the silhouette pixels the hand owns that the model leaves uncovered (coverage.hpp)
};

/// Where a re-estimate's refit of a keyframe's pose is pulled (ShapeEstimatorParams::keyframe_prior).
enum class KeyframePrior {
  kTaken,  ///< toward the pose the frame's fit gave when the keyframe was taken
  kLast,   ///< toward the keyframe's pose at the last re-estimate
};

/// Which keyframe a new one replaces once ShapeEstimatorParams::keyframes are held.
enum class KeyframeWindow {
  kNewest,   ///< the oldest: the window holds the last poses (and the estimate follows them)
  kSession,  ///< a uniformly random one, kept with probability keyframes / n for the n-th (reservoir
             ///< sampling): the window is a uniform sample of every pose since the start
};

struct ShapeEstimatorParams {
  double prior_sigma_length_m = 0.015;  ///< σ₀ of the starting profile's length [m]
  double prior_sigma_width_m = 0.008;   ///< σ₀ of its width [m]
  double prior_sigma_thickness = 0.1;   ///< σ₀ of its digits' thickness (1 = the proportions')
  int keyframes = 24;                   ///< kept (which is replaced: keyframe_window)
  /// A hand's size does not change, so a window of the newest poses throws good evidence away and
  /// lets the last part of a session decide: with kNewest the demo's right hand, 1 % narrow
  /// through the turns, ended 5–10 % wide after the release and the withdrawal, whose fast motion
  /// filled the window with open-hand poses. Each keyframe's pose is re-fitted at every
  /// re-estimate, so an old one stays valid. The draws are a hash of the candidate's count
  /// (deterministic: a replay draws the same).
  KeyframeWindow keyframe_window = KeyframeWindow::kNewest;
  double min_pose_change = 0.08;        ///< a keyframe differs from every kept one by this (‖Δθ‖, m/rad)
  /// Re-estimate after this many new keyframes per hand (an estimate of both hands after twice
  /// as many of either: its re-estimates refit twice the keyframes, so the cost per frame stays).
  int solve_every = 10;
  int min_keyframes = 6;                ///< no estimate before this many keyframes
  /// Gauss-Newton steps per re-estimate, each evaluated at the keyframes' re-fitted poses: one
  /// that raises the objective is halved back toward the best sizes visited, which are the ones
  /// kept (ShapeEstimate::objective). Measured (demo, seeds 1–2, five users and the blocks scene,
  /// 2026-11-26, late night): the widths' error 5–23 % → 1–14 % (default user 18.5 → 1.2–2.0 %), IoU alike.
  int iterations = 4;
  double freeze_sigma_length_m = 0.0003;  ///< freeze the length once its σ is below this [m]
  double freeze_sigma_width_m = 0.0003;   ///< ... the width [m]
  double freeze_sigma_thickness = 0.004;  ///< ... the thickness
  /// The estimate stays within this share of the starting sizes (0.15: ±15 %; the thickness
  /// within twice this around 1).
  double max_relative_change = 0.15;
  double difference_step_m = 1e-4;  ///< central-difference step of J_β [m]
  /// A keyframe's refit re-poses each digit whose cap misses its string by more than this
  /// (fingertip_reach.hpp) [m]: a digit stalled straight and short would bias the sizes; 0 = never.
  /// After a size step most caps move by a millimetre or so: at 1 mm every refit re-poses, which
  /// costs CPU the other threads need on a busy machine (demo, one core busy, seeds 1–3: dropped
  /// 3.1–13.1 % at 1 mm, 2.5–7.2 % at 3 mm); the small user's IoU gains less at 3 mm.
  double reach_min_miss_m = 0.003;
  /// 0: a re-estimate runs inside add_frame, on the caller's thread. N > 0: it runs on a thread of
  /// its own (at nice 0, below a frame thread at −5) from a copy of the keyframes, and its sizes
  /// take effect at the N-th poll() after it started, which waits for it then if it has not
  /// finished: the frame thread does not carry the re-estimate (10–25 ms), and the sequence of
  /// models stays the same from run to run. (At nice 10 a busy machine starved it past 2 frames,
  /// and the frame thread waited. At 5 frames, the demo's frame thread still waited 19–166 ms in
  /// about 1 % of its frames on the slower VM; at 15 (configs/registration.yaml), 3 ms at most.)
  int apply_after_frames = 0;
  /// kSpill, kBoth: keyframes also keep their silhouette (the matte ≥ matte_threshold), and with
  /// kBoth the silhouette pixels their hand owned (ImageEvidence::coverage); the re-estimate fits
  /// them and estimates the thickness too.
  ///
  /// Measured (demo, seeds 1–3, users of configs/hands.yaml and ±10 %, 2026-11-25): neither is
  /// the default. kBoth lets the uncovered pixels (webs, pads and palm tissue that capsules lack:
  /// about ten times the spill's pull on the width) grow a small user's hand to +12 % length and
  /// +15 % width. kSpill, which such tissue cannot bias (a real hand holds the model's capsules,
  /// not the reverse), brings a small user's length from +10 % to +4–7 %, but cannot grow a hand
  /// the strings do not (a large user's width stays −10 %) and narrowed a short, wide user's to
  /// the −15 % bound.
  ShapeSilhouette silhouette = ShapeSilhouette::kNone;
  /// The frame pipeline offers a frame to the estimator only when its fit's fingertip cost per
  /// fingertip is at most this (dimensionless: 4 = each fingertip 2 σ from the strings, 3 mm at
  /// 1.5 mm; FramePipeline). Demo, seeds 1–2, before digits were re-posed to their strings
  /// (fingertip_reach.hpp): the small user's right length ran to its +15 % bound without it
  /// (24–28 % off, IoU 0.726), 10 % off with it (IoU 0.745–0.746). A model of the wrong size
  /// cannot bring its caps to the strings, so the gate also keeps out the frames that say so.
  double max_fingertip_cost = 4.0;
  /// The frame pipeline offers a frame to the estimator only when the hand's fingertips moved at
  /// most this fast since the previous frame (the fastest of the four, from the strings) [m/s];
  /// 0 = no gate. A moving hand's frame mixes times: the camera's rows are exposed one after
  /// another during its readout, and the strings are sampled at one instant, so its image and its
  /// fingertips disagree by the motion, which the sizes would absorb.
  double max_keyframe_speed_m_s = 0.0;
  /// A session's two hands are one person's: the frame pipeline keeps one estimate for both
  /// (their sizes stay in the ratio of their starting profiles), so either hand's keyframes are
  /// evidence on both. The hand that holds the cube shows the camera the back of its palm, its
  /// fingers hidden behind it, and its length stays unobserved on its own; the other hand's
  /// keyframes measure it too. false: an estimate per hand.
  ///
  /// The default since session 51, with keyframe_prior_scale 2 (below): demo, 14 cases
  /// interleaved (the default user seeds 1–4, the other users and the blocks scene seeds 1–2):
  /// IoU higher in 13 (mean +0.007), joints lower in 13 (−0.42 px), the worse hand's width 10.7 %
  /// off at most instead of 12.4 %, the lengths 4.0 % instead of 5.7 %; the default user's
  /// widths within 1.3 % and lengths 1.7–2.0 % short in all four (docs/measurements.md,
  /// session 51). Before (with the prior at 1), on scenes/blocks.xml it had left both hands 9.6 %
  /// narrow and the contested pixels 14 % wrong. The frame pipeline fits both hands side by side
  /// and offers their frames to the estimate after both fits, left hand first.
  bool shared_hands = true;
  /// A re-estimate re-fits each keyframe's pose with the fit's temporal prior toward that
  /// keyframe's last pose (fingertips and the wrist pixel alone leave a hand's pose
  /// underdetermined), its σ (RegistrationParams::prior_sigma_*) multiplied by this.
  ///
  /// Measured (2026-11-25, night): the prior anchors each keyframe's pose where the fits made with
  /// earlier sizes put it, so the sizes drift along the strings' flat direction (longer) even
  /// where the model is exact: started at the true sizes with exact skeleton data
  /// (test_shape_estimator's feed(), 400 frames), the estimate ends 1.8–13.6 % long at 1, 1.2–2.4 %
  /// at 10. But in the registration study (anatomical hands) 10 stops the long-narrow user's
  /// length from converging (0.1972 m for 0.209) and the small user's worsens.
  ///
  /// 2 since session 51, with shared_hands (above): a keyframe's pose moves with the sizes, so the
  /// sizes are less held where earlier estimates put them (the large user's widths −10 → −5 %).
  /// At 3 the IoU rose as much, but the default user's widths ran +6…+12 % wide; with an estimate
  /// per hand the holding (left) hand's width ran +7…+19 % wide at 3 (docs/measurements.md,
  /// session 51).
  double keyframe_prior_scale = 2.0;
  /// The mean of that prior. kLast follows each keyframe's pose from re-estimate to re-estimate,
  /// so the poses and the sizes walk together along the strings' flat side (a longer hand bends
  /// its fingers): started at the true sizes, exact skeleton data (test_shape_estimator's feed(),
  /// linear coupling, 400 frames) end 13.6 % long, and the study's short-wide user (`--model-user
  /// --personalise`) +9 % long, −14 % wide. kTaken keeps every keyframe's prior where the frame's
  /// own fit put it: 0.25 % and +1.4 %, −0.3 %: the truth stays (nearly) a fixed point.
  KeyframePrior keyframe_prior = KeyframePrior::kLast;
  /// Keyframes also keep their silhouette (the matte ≥ matte_threshold), and a re-estimate's refits
  /// take the paper's joint-balls from it (eq. 21, recomputed at each refit's pose): they see
  /// where a finger bent to reach its cap with a too-long model leaves the real finger's
  /// silhouette, which bounds the length from above where the strings do not. The balls inform
  /// the length only (their rows are left out of the width's derivative: a ball's neighbours sit
  /// the capsule's radius from the joint, and the width scales the capsules; with them the
  /// registration study's default user's width went 7–12 % narrow), and the thickness stays.
  ///
  /// Measured (demo, seeds 1–2, five users, 2026-11-26): the small user's length error 10–11 % →
  /// 1.6–2.9 %, IoU 0.713–0.740 → 0.797–0.838; the short-wide user's 11–12 % → 0.3–1.6 %, IoU
  /// 0.598–0.656 → 0.752–0.770; the default user's IoU 0.861–0.862 → 0.854–0.856.
  bool joint_balls = true;
  /// The palm's breadth in the image (palm_breadth.hpp) as evidence on the width: a keyframe
  /// whose palm is seen nearly face on keeps its chord, and a re-estimate fits the model palm's
  /// chord to it with this σ [px]; 0 = off. (The strings alone leave the width weakly seen: a
  /// narrower hand reaches the same fingertips by spreading its fingers.)
  double palm_breadth_sigma_px = 0.0;
  PalmChordParams palm_chord;
  /// The keyframes' refits also take the digits' axes (RegistrationParams::digit_axis_sigma_px)
  /// when the frames' fits do. Measured with the axes on (demo, 18 runs): with them in the refits
  /// the left hand's width ended 12 % narrow for the default user and 20–23 % for the large one
  /// (the axes' rows hold each keyframe's digits where the fit put them, and the width gives
  /// way); without them 1–2 % and 14–18 % (the axes off: 1–6 %, 10–13 %).
  bool digit_axes = false;
  /// The fingers' middle phalanges seen across (digit_sections, residuals.hpp) when a keyframe is
  /// taken, at the frame's fitted pose: each section's width against the model capsule's
  /// projected diameter gives the capsules' radius scale (width × thickness) it implies. The
  /// re-estimates fit log(β_width β_thickness / implied) with this σ per section (dimensionless;
  /// 0 = off) over every section measured so far (the last 400), not only the keyframes held.
  /// Two-sided, so neither the webs nor a finger's tissue beyond the capsule push it one way:
  /// evidence on the capsules' radius, which the width scales (and the thickness, where it is
  /// estimated). Sections whose ratio is beyond 1.25 either way (two fingers side by side, a
  /// finger partly hidden) are left out. With it the thickness is estimated too (width and
  /// thickness share the sections; the strings and the joint-balls see the width's other
  /// effects). Measured (demo, 14 cases: five users, both scenes, 2026-11-27): the widths' error
  /// on the worse hand 7.3 → 4.8 % (max 18.3 → 9.5 %), IoU 0.829 → 0.837, joints 7.5 → 7.1 px,
  /// the contested pixels 2.4 → 2.1 % wrong (max 5.3 → 3.6 %).
  double digit_section_sigma = 0.3;
  /// A section is kept only where both its edges lie at least 2 px outside every other part of the
  /// hand's model outline at the frame's fitted pose (section_clearance_px, coverage.hpp): an edge
  /// inside another part, or on its boundary, may be that part's (a neighbouring finger partly
  /// behind this one, merged with it in the matte), and reads the digit wide. Measured (demo, 2026-11-29,
  /// session 49): without it every section of the default user's left hand came from its middle
  /// finger, each edge 1–6 px inside a neighbour's outline, reading it 1.08–1.33 times the model's
  /// width, and the left width ended 8–15 % wide; with it −0.4…+2.9 % (seeds 1–6), −2.0…+3.7 %
  /// over seeds 1–20, at 0.007 less IoU (docs/measurements.md).
  bool digit_section_clear_edges = true;
  /// Evidence accumulated over the whole session (honline's cumulative prior, Tkach et al. 2017):
  /// a keyframe leaving the window hands its information on the sizes to the prior — the quadratic
  /// its rows gave at the last re-estimate, S_k and g_k (Schur complement, file comment) at the
  /// sizes then, β*: H_p += S_k, h_p += S_k β* + g_k, from H_p = Σ₀⁻¹, h_p = Σ₀⁻¹ β₀ — so a
  /// re-estimate weighs every pose seen, not only the `keyframes` held, and σ is the session's.
  /// false: the prior stays the starting profile's, and the estimate follows the window, which
  /// the task's phases bias in turn (the default user's right length swung 182–196 mm, its width
  /// 80–86 mm, and ended 3–4 % wide after the release's keyframes). Measured (demo, 14 pairs
  /// interleaved: the default user seeds 1–4, the other users and the blocks scene seeds 1–2,
  /// docs/measurements.md, session 50): IoU higher in 12 of 14 (mean 0.846 → 0.851; short-wide
  /// +0.017), joints lower in 10 of 14 (6.58 → 6.43 px); the default user's right width
  /// +3.2…+3.8 → −1.9…+1.5 % and the short-wide user's left −8 → ±2 %, but the worse hand's
  /// width 5.7 → 6.6 % off on average: the small user's left (+2…+6 → +9 %), the long-narrow
  /// user's (to ±5 %), the large user's right (−8 → −11 %), the blocks scene's right (−4 → −11 %).
  bool accumulate = true;
  /// The caps' offset along the distal bone (HandDimensions::fingertip_offset's y) from the image:
  /// where each fingertip's outline ends beyond its string's cap (fingertip_end.hpp), measured
  /// when a frame is offered past the pose-change gate, pooled over the session (the last 400,
  /// within cap_offset_max_change_m of the starting profile's reach), and the model's offset set
  /// to the pool's median once it holds cap_offset_min_samples. The strings alone do not determine
  /// it (a cap worn further back is reached as well by a longer or more bent finger: session 50's
  /// offset estimated among the sizes moved 0.3 of 2 mm in a unit test, and the wrong way in the
  /// demo). Off: on the simulated rig it changed nothing measurable (demo, 8 cases interleaved,
  /// 2026-11-29: IoU 0.8537 both, joints 6.26 → 6.28 px). The holding (left) hand's fingers gave
  /// 15–30 samples a run reading 9.1–10.0 mm for caps 9 mm back (the simulated skin reaches 0.5 mm
  /// beyond the bone); the turning hand's fingertips are seldom seen side on and clear of the
  /// other hand, and gave none; docs/measurements.md, session 51.
  bool cap_offset_from_image = false;
  int cap_offset_min_samples = 15;
  double cap_offset_max_change_m = 0.004;  ///< [m]
  FingertipEndParams fingertip_end;  ///< the measurement's checks
};

/// The estimate of one hand (for an estimator of both hands, the shared estimate in that hand's
/// sizes).
struct ShapeEstimate {
  double length_m = 0;
  double width_m = 0;
  double sigma_length_m = 0;  ///< [m]
  double sigma_width_m = 0;
  double thickness = 1;  ///< the digits' thickness (HandDimensions::thickness)
  double sigma_thickness = 0;
  bool length_frozen = false;
  bool width_frozen = false;
  bool thickness_frozen = false;
  int keyframes = 0;  ///< keyframes held (of this hand)
  int solves = 0;     ///< re-estimates made
  /// The last re-estimate's objective (Σ_k ‖r_k‖² over its keyframes, each pose re-fitted at the
  /// sizes, plus the sizes' prior; dimensionless) at the sizes it started from and at those it
  /// kept: the kept ones are the lowest it visited, so objective ≤ objective_start.
  double objective_start = 0;
  double objective = 0;
  int steps_rejected = 0;  ///< Gauss-Newton steps that raised the objective (halved back), all re-estimates
  int palm_chords = 0;     ///< keyframes held (of this hand) with a palm chord (palm_breadth_sigma_px)
  /// The fingertip's reach beyond its cap the model now has (−fingertip_offset.y) [m], the
  /// image's samples pooled (ShapeEstimatorParams::cap_offset_from_image; of both hands for an
  /// estimator of both), and the pool median's σ (1.25 × 1.4826 MAD / √n) [m].
  double cap_reach_m = 0;
  double sigma_cap_reach_m = 0;
  int cap_reach_samples = 0;
  /// The digits' sections pooled (digit_section_sigma; of both hands for an estimator of both).
  int sections = 0;
};

class ShapeEstimator {
 public:
  /// One hand: starts from `start` (its length and width; side, coupling and limits are kept).
  explicit ShapeEstimator(const hand::HandModel& start, const ShapeEstimatorParams& params = {});
  /// Both hands of one person, indexed as in `starts` ({left, right} in the frame pipeline): one
  /// estimate β for both, hand h's sizes β ⊙ (start_h ⊘ start_0), so their profiles' ratio is kept
  /// and every keyframe, of either hand, is evidence on β. Each hand keeps its own
  /// ShapeEstimatorParams::keyframes.
  explicit ShapeEstimator(const std::array<hand::HandModel, 2>& starts,
                          const ShapeEstimatorParams& params = {});
  /// Offers one frame of hand `hand` (0 for a one-hand estimator): `q` the pose fitted with
  /// model(hand), `observation` what the fit used, `image` its camera and
  /// (ShapeEstimatorParams::silhouette) the silhouette pixels the hand owns, `fit_params` the
  /// fit's settings. Returns true when the sizes changed (every model(h) was rebuilt). With
  /// apply_after_frames > 0 it starts the re-estimate and returns false; poll() applies it.
  bool add_frame(int hand, const hand::HandParams& q, const HandObservation& observation,
                 const ImageEvidence& image, const RegistrationParams& fit_params);
  bool add_frame(const hand::HandParams& q, const HandObservation& observation,
                 const ImageEvidence& image, const RegistrationParams& fit_params) {
    return add_frame(0, q, observation, image, fit_params);
  }
  /// Call once per frame (before fitting with model()) when apply_after_frames > 0: applies a
  /// re-estimate started apply_after_frames polls ago, waiting for it if needed. Returns true when
  /// the sizes changed (the models were rebuilt). Without a re-estimate in flight it does nothing.
  bool poll();
  /// Whether a re-estimate is running on its own thread.
  bool solving() const { return pending_.valid(); }
  /// How many hands the estimate covers (1 or 2).
  int hands() const { return static_cast<int>(models_.size()); }
  /// Hand `hand`'s model at the current estimate (hand in [0, hands())).
  const hand::HandModel& model(int hand = 0) const { return models_.at(static_cast<std::size_t>(hand)); }
  /// The estimate in hand `hand`'s sizes, with that hand's keyframe count.
  ShapeEstimate estimate(int hand = 0) const;

  ShapeEstimator(ShapeEstimator&&) = default;
  ShapeEstimator& operator=(ShapeEstimator&&) = default;
  ~ShapeEstimator();

 private:
  struct Keyframe {
    int hand = 0;
    std::uint64_t serial = 0;  ///< order of arrival (the oldest of a hand is replaced)
    hand::HandParams q;        ///< its pose at the last re-estimate's sizes
    hand::HandParams q_taken;  ///< the pose the frame's fit gave when it was taken
    HandObservation observation;
    std::vector<OwnedPixel> owned;  ///< ShapeEstimatorParams::silhouette only
    /// CV_8UC1, the matte ≥ matte_threshold, 255 = hand (ShapeEstimatorParams::silhouette, and
    /// the joint-balls' matte with joint_balls)
    cv::Mat silhouette;
    /// The silhouette's distance transform, made by the first re-estimate that uses it (read only
    /// from then on, so copies on a re-estimate's thread share it).
    std::shared_ptr<const vision::SilhouetteDistance> distance;
    std::optional<PalmChord> chord;  ///< the palm's breadth (palm_breadth_sigma_px > 0)
    /// Its information on β at the last re-estimate that held it (ShapeEstimatorParams::accumulate):
    /// the quadratic c(β) ≈ c* − 2 gᵀ(β − β*) + (β − β*)ᵀ S (β − β*), β* = beta_lin; S = 0 until
    /// a re-estimate has held it.
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    Eigen::Vector3d beta_lin = Eigen::Vector3d::Zero();
  };
  /// What one re-estimate starts from, and what it ends with (plain copies: a re-estimate on its
  /// own thread shares nothing with the estimator).
  struct Solve {
    ShapeEstimatorParams params;
    RegistrationParams fit_params;
    std::optional<vision::Camera> camera;
    std::vector<hand::HandModel> models;  ///< per hand
    std::vector<Eigen::Vector3d> starts;  ///< per hand: starting (length [m], width [m], thickness)
    std::vector<Keyframe> keyframes;
    std::vector<double> section_sizes;  ///< ShapeEstimator::section_sizes_
    Eigen::Matrix3d prior_H;  ///< ShapeEstimator::prior_H_
    Eigen::Vector3d prior_h;  ///< ShapeEstimator::prior_h_
    ShapeEstimate estimate;  ///< in hand 0's sizes (β)
    bool changed = false;
  };
  /// One re-estimate (the file comment's Gauss-Newton on β over the keyframes), on copies.
  static Solve run_solve(Solve job);
  Solve make_solve(const vision::Camera* camera, const RegistrationParams& fit_params) const;
  bool apply(Solve&& done);
  /// Measures the fingers' middle phalanges' sections of hand `hand` at pose `q` into section_sizes_.
  void add_sections(int hand, const hand::HandParams& q, const vision::Camera& camera, const cv::Mat& alpha,
                    double threshold);
  /// Measures the fingertips' reach beyond their caps (fingertip_end.hpp) into cap_reaches_.
  void add_fingertip_ends(int hand, const hand::HandParams& q, const HandObservation& observation,
                          const vision::Camera& camera, const cv::Mat& alpha, double threshold);
  /// The image measures of an offered frame (sections, fingertip ends), as the settings ask.
  void add_image_measures(int hand, const hand::HandParams& q, const HandObservation& observation,
                          const ImageEvidence& image, const RegistrationParams& fit_params);
  /// Sets every model's cap offset to the pool's median once it is large enough (cap_offset_*);
  /// true when the models changed.
  bool update_cap_offset();
  /// Every model in `models` with the fingertip's reach `reach_m` beyond the cap; false (models
  /// unchanged) if a model cannot be built with it.
  static bool set_cap_reach(std::vector<hand::HandModel>* models, double reach_m);

  ShapeEstimatorParams p_;
  std::vector<hand::HandModel> models_;
  std::vector<Eigen::Vector3d> starts_;  ///< per hand: starting (length [m], width [m], thickness)
  std::vector<Keyframe> keyframes_;
  /// The digits' sections measured when keyframes were taken (digit_section_sigma), each as the
  /// capsules' radius scale it implies in β's units (width [m] × thickness), oldest first. Pooled
  /// across keyframes, kept when they are replaced: the fingers are seen across in some parts of a
  /// session only (the holding hand's hardly ever), and what they showed stays true.
  std::vector<double> section_sizes_;
  /// The fingertips' reach beyond their caps measured in the image (cap_offset_from_image) [m],
  /// oldest first, the last 400.
  std::vector<double> cap_reaches_;
  double start_cap_reach_m_ = 0;  ///< the starting profile's (−fingertip_offset.y) [m]
  double cap_reach_m_ = 0;        ///< the models' now [m]
  double sigma_cap_reach_m_ = 0;  ///< [m]
  /// The sizes' prior in information form, βᵀ H β − 2 hᵀ β: the starting profile's (Σ₀⁻¹, Σ₀⁻¹ β₀),
  /// plus, with ShapeEstimatorParams::accumulate, what the keyframes that left the window knew.
  Eigen::Matrix3d prior_H_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d prior_h_ = Eigen::Vector3d::Zero();
  /// Adds keyframe `k`'s information to the prior (accumulate) before it leaves the window.
  void absorb(const Keyframe& k);
  std::uint64_t next_serial_ = 0;
  std::vector<std::uint64_t> candidates_;  ///< per hand: new poses offered (KeyframeWindow::kSession)
  int new_since_solve_ = 0;
  ShapeEstimate estimate_;  ///< in hand 0's sizes (β)
  std::future<Solve> pending_;
  int polls_since_start_ = 0;
};

/// Reads a `personalisation:` map (every key optional): enabled (bool, into `*enabled`),
/// prior_sigma_length_m, prior_sigma_width_m, prior_sigma_thickness, keyframes, min_pose_change,
/// solve_every, min_keyframes, iterations, freeze_sigma_length_m, freeze_sigma_width_m,
/// freeze_sigma_thickness, max_relative_change,
/// reach_min_miss_m, apply_after_frames, silhouette, max_fingertip_cost, max_keyframe_speed_m_s, shared_hands,
/// keyframe_prior_scale, keyframe_prior (taken or last), keyframe_window (newest or session),
/// joint_balls, palm_breadth_sigma_px, palm_breadth_at, palm_breadth_min_facing, digit_axes,
/// digit_section_sigma, digit_section_clear_edges, accumulate, cap_offset_from_image,
/// cap_offset_min_samples, cap_offset_max_change_m.
/// Throws core::ConfigError naming file:line: key and the expected range.
ShapeEstimatorParams parse_shape_estimator_params(const core::ConfigNode& node, bool* enabled);

/// The model `m` with other sizes (same side, coupling, limits and, in the first form,
/// thickness). Fails on invalid sizes.
Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m);
Result<hand::HandModel> resized(const hand::HandModel& m, double length_m, double width_m,
                                double thickness);

}  // namespace spidar::registration
