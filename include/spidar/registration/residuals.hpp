#pragma once
/// The residuals of the successive adjustment (successive_adjustment.hpp) with their image targets
/// frozen: what one linearisation holds fixed. Exposed for tests (the Jacobian against finite
/// differences, the optimum against a generic solver) and diagnostics; the solver itself never
/// stacks them (it accumulates the normal equations block by block).
///
/// Residual blocks, each divided by its σ (registration_params.hpp), in this order:
///   fingertip  p_W_fingertip(θ) − p̃_W (3 rows per valid, finite fingertip)            [m / m]
///   wrist      √conf · (uv(p_W_bracelet(θ)) − wrist_px) / σ_wrist (2 rows)              [px / px]
///              p_W_bracelet = p_W_wrist + R_WH·(bracelet_offset_m · forearm_H) + s_W, with s_W the
///              frozen shift to the band's visible surface (bracelet_visible_point)
///   band       √conf · dz(‖uv(e₁(θ)) − uv(e₀(θ))‖ / wrist_length_px − 1) / σ_band, dz(x) =
///              sign(x)·max(|x| − tolerance, 0) (1 row, where the band's length is measured and
///              bracelet_length_sigma > 0): the band's projected length across the forearm, from
///              its two ends e₀, e₁ frozen in the hand frame (bracelet_band_ends), relative to
///              the detected one, with a dead zone of bracelet_length_tolerance          [1 / 1]
///   thickness  the same for the band's extent across its long axis in the image, from its two
///              frozen extreme points (bracelet_band_thickness), against wrist_thickness_px
///              (1 row, where bracelet_thickness_sigma > 0; counted with the band)       [1 / 1]
///   joint-ball (uv(joint j)(θ) − P̃_j) / σ_ball (2 rows per ball with on_count ≥ 1)       [px / px]
///   silhouette (uv(axis point)(θ) + offset − nearest) / σ_sil (2 rows per point found outside
///              the real silhouette by more than 0.5 px when frozen)                      [px / px]
///   coverage   (uv(edge point)(θ) − owned pixel) / σ_cov (2 rows per silhouette pixel this hand
///              owns and leaves uncovered by more than 0.5 px when frozen; coverage.hpp)  [px / px]
///   digit axis n·(uv(axis point)(θ) − midpoint) / σ_axis, n across the projected bone (1 row per
///              phalanx section whose two silhouette edges were found when frozen, with the
///              silhouette term and digit_axis_sigma_px > 0; counted with the joint-balls' cost:
///              both are the digits' joints and axes read from the matte)            [px / px]
///   prior      (θ_i − θ_prior,i) / σ_group (1 row per parameter with a finite prior: the
///              paper's 17, and the little finger's own 3 where q.little_independent)
///   coupling   (θ_little,k − θ_ring,k) / σ_little (3 rows, only where q.little_independent;
///              counted with the prior's cost)
/// Frozen with the targets: the joint-ball targets P̃, each silhouette point's nearest silhouette
/// pixel and its offset from the projected axis point (± the projected radius across the bone),
/// whether the wrist term is active (bracelet point in front of the camera), the bracelet's
/// visible-surface shift and the band's two ends, and each digit axis section's midpoint.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/joint_balls.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/registration/successive_adjustment.hpp"

namespace spidar::registration {

/// Bones sampled by the silhouette term: the thumb's 3 (metacarpal, proximal, distal), then 4 per
/// finger (metacarpal, proximal, middle, distal) for index, middle, ring, little.
inline constexpr int kSilhouetteBoneCount = 3 + 4 * 4;  // 19
inline constexpr int kMaxSilhouettePoints =
    kSilhouetteBoneCount * kMaxSilhouetteSamplesPerBone * 3;
/// At most this many uncovered silhouette pixels per linearisation (coverage.hpp); more owned
/// pixels are thinned evenly.
inline constexpr int kMaxCoveragePoints = 768;

/// Finger and segment (0 = metacarpal, hand_shape.hpp) of silhouette bone `bone` (0..18).
struct BoneRef {
  int finger;
  int segment;
};
BoneRef silhouette_bone(int bone);

/// A digit's axis in the image (RegistrationParams::digit_axis_sigma_px): the point at t along
/// silhouette bone `bone` is pulled across the bone, along `across_px`, onto `target_px`, the
/// midpoint of the silhouette's edges there (frozen at the linearisation).
struct DigitAxisPoint {
  int bone = 0;
  double t = 0;
  Vec2 across_px = Vec2::Zero();  ///< unit, across the projected bone
  Vec2 target_px = Vec2::Zero();  ///< [px]
  double width_px = 0;        ///< the silhouette's section across the bone [px]
  double model_width_px = 0;  ///< the model capsule's outline across the bone there, in perspective [px]
};
/// Phalanges sampled (thumb 2, fingers 3 each) × points along each.
inline constexpr int kMaxDigitAxisPoints = 14 * 2;

/// The digits' sections of hand `model` at pose `q` in the matte `alpha` (CV_32FC1 in [0, 1], or
/// CV_8UC1 read as /255; anything else, or a non-finite pose: none): across each phalanx, at 1/3
/// and 2/3 of it, the matte walked out both ways from the projected axis to its edges (at
/// `threshold`). A section is left out when its width is not within 0.5–1.8 times the model
/// capsule's projected diameter, or its midpoint lies more than the radius from the axis. What the
/// digit axes pull toward (the midpoints), and the size estimate's evidence on the digits'
/// thickness (the widths against the model's outline; ShapeEstimatorParams::digit_section_sigma).
std::vector<DigitAxisPoint> digit_sections(const hand::HandModel& model, const hand::HandParams& q,
                                           const vision::Camera& camera, const cv::Mat& alpha,
                                           double threshold);

/// One silhouette sample that lies outside the real silhouette (frozen at the linearisation).
struct SilhouettePoint {
  int bone = 0;                  ///< 0..18 (silhouette_bone); −1: the palm box's point palm_u
  double t = 0;                  ///< along the bone axis: 0 proximal joint, 1 distal joint
  Vec2 offset_px = Vec2::Zero(); ///< from the projected axis point to this point [px]
  Vec2 target_px = Vec2::Zero(); ///< the nearest silhouette pixel [px]
  /// Bone −1: the point on the palm box in box units, (p_H − centre) / half_extents per axis
  /// (right-hand H), so that it stays on the box when the model's sizes change.
  Vec3 palm_u = Vec3::Zero();
  /// Bones: the bone's capsule radius when frozen [m]; offset_px scales with the model's radius
  /// over it (1 while the model is the one frozen with; a size estimate's resized models move the
  /// edge with the capsule). 0: offset_px as is.
  double radius_m = 0;
  double weight = 1.0;           ///< robust weight (coverage: Huber at coverage_huber_px), 0..1
};

/// Everything one linearisation holds fixed. Plain fixed-size storage (about 30 KiB).
struct FrozenTargets {
  bool wrist_active = false;
  /// From the band centre to its visible surface's centre, toward the camera (world) [m]
  /// (bracelet_visible_shift at the linearisation).
  Vec3 bracelet_shift_W = Vec3::Zero();
  /// The band term (bracelet_band_ends at the linearisation): whether it acts, and the band's
  /// two ends in right-hand H coordinates [m] (rigid with the hand until the next freeze).
  bool band_active = false;
  std::array<Vec3, 2> band_end_H{Vec3::Zero(), Vec3::Zero()};
  /// The band's thickness term (bracelet_band_thickness at the linearisation): whether it acts,
  /// the two points of the band's near side farthest apart across its image axis, right-hand H
  /// [m], and that direction in the image (unit, frozen).
  bool thickness_active = false;
  std::array<Vec3, 2> thickness_end_H{Vec3::Zero(), Vec3::Zero()};
  Vec2 thickness_dir_px = Vec2::Zero();
  JointBalls balls{};
  std::array<SilhouettePoint, kMaxSilhouettePoints> silhouette{};
  int silhouette_count = 0;  ///< entries of `silhouette` in use
  /// Owned silhouette pixels the pose leaves uncovered, each with the nearest part's edge point
  /// (coverage.hpp): target_px is the pixel, offset_px the edge point's offset from the axis
  /// point (bones) or zero (palm).
  std::array<SilhouettePoint, kMaxCoveragePoints> coverage{};
  int coverage_count = 0;
  std::array<DigitAxisPoint, kMaxDigitAxisPoints> axes{};
  int axis_count = 0;  ///< entries of `axes` in use
};

/// What the residuals are about besides the parameters. Pointers are borrowed; `prior` may be
/// null (no prior term).
struct ResidualProblem {
  const hand::HandModel* model = nullptr;
  const HandObservation* observation = nullptr;
  const ImageEvidence* image = nullptr;
  const hand::HandParams* prior = nullptr;
  const RegistrationParams* params = nullptr;
};

/// The band's radius [m] on a hand `hand_width_m` broad: the forearm's radius there
/// (bracelet_radius_per_width × width) plus the band's standoff.
inline double bracelet_radius_m(const RegistrationParams& params, double hand_width_m) {
  return params.bracelet_radius_per_width * hand_width_m + params.bracelet_standoff_m;
}

/// Where the bracelet's detected midpoint should lie for a hand at pose `X_WH` seen from
/// `p_W_camera` (world, m): the band centre, bracelet_offset_m from the wrist toward the elbow,
/// shifted toward the camera across the forearm by bracelet_surface_shift × the band's radius
/// (registration_params.hpp). `shift_W` (optional) receives the shift alone. `forearm_H`: the
/// forearm's direction toward the elbow in right-hand H coordinates (HandObservation::forearm_H;
/// unit, (0, −1, 0) in line with the hand).
Vec3 bracelet_visible_point(const Pose& X_WH, double hand_width_m, const Vec3& p_W_camera,
                            const RegistrationParams& params, Vec3* shift_W = nullptr,
                            const Vec3& forearm_H = Vec3(0.0, -1.0, 0.0));

/// The band's two ends across the forearm as seen from `p_W_camera` (world, m), for a hand at
/// pose `X_WH` (the x axis's sign does not matter): the forearm's section at the band is an
/// ellipse centred bracelet_offset_m from the wrist toward the elbow, with half axes
/// bracelet_radius_m across the hand (x_H) and bracelet_depth_ratio × the forearm's half breadth
/// + standoff dorsal-palmar (z_H); its ends are the ellipse's support points in the direction
/// across the forearm and the line of sight, w = y_H × (centre − camera). [m]
std::array<Vec3, 2> bracelet_band_ends(const Pose& X_WH, double hand_width_m, const Vec3& p_W_camera,
                                       const RegistrationParams& params);

/// The band's projected length across the forearm [px]: the distance between its two ends'
/// projections (bracelet_band_ends). 0 when an end is behind the camera.
double bracelet_length_px(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                          const RegistrationParams& params);

/// The band's near side in the image for a hand at pose `X_WH` (the points of both rims,
/// bracelet_width_m apart along the forearm around bracelet_offset_m, whose outward normal faces
/// the camera; the section as in bracelet_band_ends), projected and measured along `across_px`
/// (unit, image), from `samples_per_rim` points around each rim (8..96). All zero when a sampled
/// point is behind the camera.
struct BandProfile {
  double lo_px = 0, hi_px = 0;  ///< its extent along across_px (image coordinates dotted with it) [px]
  double centroid_px = 0;       ///< its area's centroid along across_px [px]
  double area_px = 0;           ///< its area [px²]
  std::array<Vec3, 2> ends{Vec3::Zero(), Vec3::Zero()};  ///< the points giving lo and hi (world) [m]
};
BandProfile bracelet_band_profile(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                                  const RegistrationParams& params, const Vec2& across_px,
                                  int samples_per_rim = 48);

/// Where vision/bracelet.cpp's detector would put the band's midpoint (its projected wrist) [px]:
/// the band's near side (as in bracelet_band_profile) for a forearm at pose `X_WF` (the forearm's
/// frame: hand::wrist_bend applied to the hand's rotation, the band around its −y axis), its
/// area's centroid and major axis in the image, and the midpoint of its extent along that axis,
/// the centroid's place across it, as the detector takes them from the red pixels. nullopt when
/// a near point is behind the camera or the near side has no area.
std::optional<Vec2> bracelet_midpoint_px(const Pose& X_WF, double hand_width_m, const vision::Camera& camera,
                                         const RegistrationParams& params, int samples_per_rim = 32);

/// The band's thickness in the image for a hand at pose `X_WH`: the extent of its near side
/// (bracelet_band_profile) along `across_px` (unit, image). `ends` (optional) receives the two points giving the extent (world).
/// 0 when a sampled point is behind the camera.
double bracelet_band_thickness(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                               const RegistrationParams& params, const Vec2& across_px,
                               std::array<Vec3, 2>* ends = nullptr);

/// Recomputes the image targets at pose `q` (joint-balls, silhouette points, wrist activity).
void freeze_targets(const ResidualProblem& problem, const hand::HandParams& q,
                    FrozenTargets* targets);

/// The per-term costs (squared norms of the residual blocks) at `q` with frozen targets.
TermCosts term_costs(const ResidualProblem& problem, const FrozenTargets& targets,
                     const hand::HandParams& q);

/// Which term a stacked residual row belongs to (the blocks above; coverage rows count as
/// silhouette, coupling rows as prior; the band's cost counts with the wrist's in TermCosts).
enum class ResidualTerm : std::uint8_t { kFingertip, kWrist, kBand, kJointBall, kSilhouette, kPrior };

/// The stacked residual vector and, if `J` is non-null, its Jacobian (rows × 20) at `q` with
/// frozen targets; if `terms` is non-null, each row's term. Allocates: for tests, diagnostics and
/// the size estimator.
void stacked_residuals(const ResidualProblem& problem, const FrozenTargets& targets,
                       const hand::HandParams& q, VecX* r, MatX* J,
                       std::vector<ResidualTerm>* terms = nullptr);

}  // namespace spidar::registration
