#include "spidar/registration/residuals.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "spidar/core/units.hpp"
#include "spidar/hand/forearm.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/vision/bracelet.hpp"

#include "residual_terms.hpp"

namespace spidar::registration {

BoneRef silhouette_bone(int bone) {
  if (bone < 3) return {hand::kThumb, bone};
  return {hand::kIndex + (bone - 3) / 4, (bone - 3) % 4};
}

namespace {

/// Silhouette points of one pose: for each bone, samples at t = (i + ½)/n on its axis and two
/// edge points ± the projected capsule radius across the projected bone; those farther than
/// the tolerance from the real silhouette are kept with their nearest silhouette pixel.
void freeze_silhouette(const ResidualProblem& pr, const detail::PoseState& s,
                       const vision::Camera& camera, const vision::SilhouetteDistance& dist,
                       FrozenTargets* tg) {
  const hand::HandModel& model = *pr.model;
  const int n = pr.params->silhouette_samples_per_bone;
  const double focal = 0.5 * (camera.intrinsics().fx + camera.intrinsics().fy);
  for (int bone = 0; bone < kSilhouetteBoneCount; ++bone) {
    const BoneRef b = silhouette_bone(bone);
    const Vec3 a = detail::bone_end(model, s, b, 0, nullptr);
    const Vec3 c = detail::bone_end(model, s, b, 1, nullptr);
    if (camera.depth(a) < detail::kMinImageDepth || camera.depth(c) < detail::kMinImageDepth) {
      continue;
    }
    Vec2 dir = camera.project(c) - camera.project(a);
    const double len = dir.norm();
    const bool has_dir = len > 1e-6;
    if (has_dir) dir /= len;
    const Vec2 across(-dir.y(), dir.x());
    const double radius_m = model.shape.digits[b.finger].radius[b.segment];
    for (int i = 0; i < n; ++i) {
      const double t = (i + 0.5) / n;
      const Vec3 p = (1.0 - t) * a + t * c;
      const double depth = camera.depth(p);
      if (!(depth >= detail::kMinImageDepth)) continue;
      const Vec2 uv = camera.project(p);
      const double r_px = radius_m * focal / depth;
      for (int side : {0, 1, -1}) {
        if (side != 0 && !has_dir) continue;
        const Vec2 offset = (side * r_px) * across;
        const Vec2 q = uv + offset;
        const auto nearest = dist.nearest(q);
        if (!nearest || (q - *nearest).norm() <= detail::kSilhouetteTolerancePx) continue;
        if (tg->silhouette_count >= kMaxSilhouettePoints) return;
        SilhouettePoint sp{bone, t, offset, *nearest};
        sp.radius_m = radius_m;
        tg->silhouette[tg->silhouette_count++] = sp;
      }
    }
  }
}

/// The digits' sections (digit_sections): across each phalanx at t = 1/3 and 2/3, the
/// silhouette's edges either side of the projected axis, their midpoint and the width between.
int sections_of(const hand::HandModel& model, const detail::PoseState& s, const vision::Camera& camera,
                const cv::Mat& alpha, double threshold, std::span<DigitAxisPoint> out) {
  const double focal = 0.5 * (camera.intrinsics().fx + camera.intrinsics().fy);
  const Vec3 camera_centre = camera.X_WC().p;
  int count = 0;
  for (int bone = 0; bone < kSilhouetteBoneCount; ++bone) {
    const BoneRef b = silhouette_bone(bone);
    if (b.segment == 0) continue;  // the metacarpals lie in the palm
    const Vec3 a = detail::bone_end(model, s, b, 0, nullptr);
    const Vec3 c = detail::bone_end(model, s, b, 1, nullptr);
    if (camera.depth(a) < detail::kMinImageDepth || camera.depth(c) < detail::kMinImageDepth) continue;
    const Vec2 ua = camera.project(a), uc = camera.project(c);
    const double radius_m = model.shape.digits[b.finger].radius[b.segment];
    const double r_px = radius_m * focal / camera.depth(0.5 * (a + c));
    const Vec2 d = uc - ua;
    // A bone seen nearly end-on has no direction across it to measure.
    if (!(d.norm() > 2.0 * r_px) || !(r_px > 0.5)) continue;
    const Vec2 across = Vec2(-d.y(), d.x()).normalized();
    for (const double t : {1.0 / 3.0, 2.0 / 3.0}) {
      const Vec2 p = ua + t * d;
      if (!camera.in_image(p) || !vision::on_silhouette(alpha, p, threshold)) continue;
      const double max_px = 2.0 * r_px + 3.0;
      const auto plus = detail::edge_along(alpha, p, across, max_px, threshold);
      const auto minus = detail::edge_along(alpha, p, -across, max_px, threshold);
      if (!plus || !minus) continue;
      const double width = *plus + *minus;
      if (width < 0.5 * 2.0 * r_px || width > 1.8 * 2.0 * r_px) continue;
      // An axis more than the radius off may be another finger's: only a near one is this bone's.
      if (std::abs(0.5 * (*plus - *minus)) > r_px) continue;
      if (count >= static_cast<int>(out.size())) return count;
      // The capsule's own outline there, in perspective: its two silhouette generators lie at
      // ±radius across the bone and across the ray to it (a bone off the optical axis, or leaning
      // toward the camera, looks wider than 2 r f / depth).
      const Vec3 c3 = a + t * (c - a);
      const Vec3 side = (c - a).cross(c3 - camera_centre);
      double model_width = 2.0 * r_px;
      if (side.norm() > 1e-12) {
        const Vec3 u = radius_m * side.normalized();
        const Vec2 e1 = camera.project(c3 + u), e2 = camera.project(c3 - u);
        if (e1.allFinite() && e2.allFinite()) model_width = std::abs((e1 - e2).dot(across));
      }
      out[static_cast<std::size_t>(count++)] =
          DigitAxisPoint{bone, t, across, p + 0.5 * (*plus - *minus) * across, width, model_width};
    }
  }
  return count;
}

/// The digits' axes (RegistrationParams::digit_axis_sigma_px): the sections' midpoints.
void freeze_digit_axes(const ResidualProblem& pr, const detail::PoseState& s, const vision::Camera& camera,
                       const cv::Mat& alpha, FrozenTargets* tg) {
  tg->axis_count = sections_of(*pr.model, s, camera, alpha, pr.params->matte_threshold, tg->axes);
}

/// Owned silhouette pixels (ImageEvidence::coverage) that the pose leaves uncovered, each with the
/// nearest part's edge point.
void freeze_coverage(const ResidualProblem& pr, const hand::HandParams& q,
                     const vision::Camera& camera, const std::vector<OwnedPixel>& owned,
                     FrozenTargets* tg) {
  if (owned.empty()) return;
  ProjectedHand outline;
  project_hand(*pr.model, q, camera, 0.0, &outline);
  const auto n = static_cast<int>(owned.size());
  const int step = (n + kMaxCoveragePoints - 1) / kMaxCoveragePoints;
  for (int i = 0; i < n && tg->coverage_count < kMaxCoveragePoints; i += step) {
    const Vec2& px = owned[static_cast<std::size_t>(i)].px;
    // Most owned pixels stay covered by the part that covered them when the owner was decided.
    if (part_distance(outline, owned[static_cast<std::size_t>(i)].part, px) <= detail::kSilhouetteTolerancePx)
      continue;
    const OutlineNearest near = nearest_part(outline, px);
    if (!(near.distance_px > detail::kSilhouetteTolerancePx) || std::isinf(near.distance_px)) continue;
    SilhouettePoint sp;
    sp.bone = near.bone;
    sp.target_px = px;
    const double huber = pr.params->coverage_huber_px;
    sp.weight = near.distance_px > huber ? std::sqrt(huber / near.distance_px) : 1.0;
    if (near.bone >= 0) {
      const ImageCapsule& c = outline.bones[near.bone];
      sp.t = near.t;
      sp.offset_px = near.edge_px - (c.a + near.t * (c.c - c.a));
      const BoneRef b = silhouette_bone(near.bone);
      sp.radius_m = pr.model->shape.digits[b.finger].radius[b.segment];
    } else {
      const hand::PalmBox& box = pr.model->shape.palm;
      sp.palm_u = (near.palm_H - box.p_H_centre).cwiseQuotient(box.half_extents);
    }
    tg->coverage[tg->coverage_count++] = sp;
  }
}

/// The forearm's section at the band, an ellipse: half breadth a (across the hand, x_H) and half
/// depth b (dorsal-palmar, z_H) [m] (bracelet_radius_m and bracelet_depth_ratio).
std::pair<double, double> band_section(const RegistrationParams& params, double hand_width_m) {
  return {bracelet_radius_m(params, hand_width_m),
          params.bracelet_depth_ratio * params.bracelet_radius_per_width * hand_width_m + params.bracelet_standoff_m};
}

/// Collects the rows (tests only).
struct StackSink {
  std::vector<double> r;
  std::vector<Eigen::Matrix<double, 1, hand::kParamCount>> J;
  std::vector<ResidualTerm> terms;
  template <int R>
  void add(detail::Term t, const detail::Block<R>& res, const detail::BlockJacobian<R>* Jb) {
    for (int k = 0; k < R; ++k) {
      r.push_back(res[k]);
      terms.push_back(static_cast<ResidualTerm>(t));
      if (Jb) J.push_back(Jb->row(k));
    }
  }
  void add_prior(int i, double res, double j) {
    r.push_back(res);
    terms.push_back(ResidualTerm::kPrior);
    Eigen::Matrix<double, 1, hand::kParamCount> row = Eigen::Matrix<double, 1, hand::kParamCount>::Zero();
    row[i] = j;
    J.push_back(row);
  }
};

}  // namespace

Vec3 bracelet_visible_point(const Pose& X_WH, double hand_width_m, const Vec3& p_W_camera,
                            const RegistrationParams& params, Vec3* shift_W, const Vec3& forearm_H) {
  const Vec3 centre = X_WH * Vec3(params.bracelet_offset_m * forearm_H);
  const Vec3 axis = X_WH.R * forearm_H;
  Vec3 toward = p_W_camera - centre;
  toward -= toward.dot(axis) * axis;
  Vec3 shift = Vec3::Zero();
  const double n = toward.norm();
  if (n > 1e-9) {
    const double radius = bracelet_radius_m(params, hand_width_m);
    shift = (params.bracelet_surface_shift * radius / n) * toward;
  }
  if (shift_W) *shift_W = shift;
  return centre + shift;
}

std::array<Vec3, 2> bracelet_band_ends(const Pose& X_WH, double hand_width_m, const Vec3& p_W_camera,
                                       const RegistrationParams& params) {
  const Vec3 centre = X_WH * Vec3(0.0, -params.bracelet_offset_m, 0.0);
  const Mat3 R = X_WH.R.toRotationMatrix();
  const Vec3 x = R.col(0), y = R.col(1), z = R.col(2);
  const auto [a, b] = band_section(params, hand_width_m);
  Vec3 w = y.cross(centre - p_W_camera);  // across the forearm and the line of sight
  const double n = w.norm();
  if (!(n > 1e-12)) w = x;                // seen end-on: any direction across is as good
  else w /= n;
  const double wx = w.dot(x), wz = w.dot(z);
  const double support = std::sqrt(a * a * wx * wx + b * b * wz * wz);
  const Vec3 e = support > 1e-12 ? Vec3((a * a * wx / support) * x + (b * b * wz / support) * z)
                                 : Vec3(a * x);
  return {centre - e, centre + e};
}

double bracelet_length_px(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                          const RegistrationParams& params) {
  const auto ends = bracelet_band_ends(X_WH, hand_width_m, camera.X_WC().p, params);
  if (camera.depth(ends[0]) < detail::kMinImageDepth || camera.depth(ends[1]) < detail::kMinImageDepth)
    return 0.0;
  return (camera.project(ends[1]) - camera.project(ends[0])).norm();
}

namespace {

/// The band's near side sampled: both rims (bracelet_width_m apart along the forearm −y of
/// X_WH, around bracelet_offset_m), `samples` points each, the section as in bracelet_band_ends;
/// which face the camera (outward normal toward it) and their projections. false when a near
/// point is behind the camera.
struct BandNearSide {
  static constexpr int kMaxSamples = 96;
  int samples = 0;
  std::array<std::array<Vec2, kMaxSamples>, 2> image{};
  std::array<std::array<Vec3, kMaxSamples>, 2> point{};
  std::array<std::array<bool, kMaxSamples>, 2> near{};
  /// Whether the quad between samples k and k+1 of both rims is wholly on the near side.
  bool quad(int k) const {
    const int k1 = (k + 1) % samples;
    return near[0][k] && near[0][k1] && near[1][k] && near[1][k1];
  }
};

bool band_near_side(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                    const RegistrationParams& params, int samples_per_rim, BandNearSide* out) {
  const Mat3 R = X_WH.R.toRotationMatrix();
  const Vec3 x = R.col(0), z = R.col(2);  // across the forearm; y_H runs along it
  const auto [a, b] = band_section(params, hand_width_m);
  const Vec3 p_W_camera = camera.X_WC().p;
  out->samples = std::clamp(samples_per_rim, 8, BandNearSide::kMaxSamples);
  for (int r = 0; r < 2; ++r) {
    const double along = params.bracelet_offset_m + (r == 0 ? -0.5 : 0.5) * params.bracelet_width_m;
    const Vec3 rim_centre = X_WH * Vec3(0.0, -along, 0.0);
    for (int k = 0; k < out->samples; ++k) {
      const double phi = 2.0 * units::kPi * k / out->samples;
      const double c = std::cos(phi), sn = std::sin(phi);
      const Vec3 p = rim_centre + a * c * x + b * sn * z;
      const Vec3 outward = (c / a) * x + (sn / b) * z;  // the ellipse's normal (unnormalised)
      out->near[r][k] = outward.dot(p_W_camera - p) > 0.0;  // else the far side
      if (!out->near[r][k]) continue;
      if (camera.depth(p) < detail::kMinImageDepth) return false;
      out->point[r][k] = p;
      out->image[r][k] = camera.project(p);
    }
  }
  return true;
}

/// Calls f(p0, p1, p2) for the near side's triangles in the image (each patch between the rims
/// seen once: the band is convex).
template <class F>
void for_each_near_triangle(const BandNearSide& n, F&& f) {
  for (int k = 0; k < n.samples; ++k) {
    if (!n.quad(k)) continue;
    const int k1 = (k + 1) % n.samples;
    f(n.image[0][k], n.image[0][k1], n.image[1][k1]);
    f(n.image[0][k], n.image[1][k1], n.image[1][k]);
  }
}

/// The near side's area [px²], first moment [px³] and second moments about the image origin
/// [px⁴], summed over its triangles (a triangle's second moment: A/12 (Σ vᵢvᵢᵀ + (Σ vᵢ)(Σ vᵢ)ᵀ)).
struct NearSideMoments {
  double area = 0;
  Vec2 first = Vec2::Zero();
  Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
};

NearSideMoments near_side_moments(const BandNearSide& n) {
  NearSideMoments m;
  for_each_near_triangle(n, [&](const Vec2& p0, const Vec2& p1, const Vec2& p2) {
    const Vec2 e1 = p1 - p0, e2 = p2 - p0;
    const double t = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    const Vec2 sum = p0 + p1 + p2;
    m.area += t;
    m.first += t * sum / 3.0;
    m.second += (t / 12.0) * (p0 * p0.transpose() + p1 * p1.transpose() + p2 * p2.transpose() + sum * sum.transpose());
  });
  return m;
}

/// The near side's rim points' smallest and largest image coordinate along `dir` [px], and the
/// world points where they are (lo > hi when none is near).
struct NearSideExtent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  std::array<Vec3, 2> ends = zeros<Vec3, 2>();
};

NearSideExtent near_side_extent(const BandNearSide& n, const Vec2& dir) {
  NearSideExtent e;
  for (int r = 0; r < 2; ++r)
    for (int k = 0; k < n.samples; ++k) {
      if (!n.near[r][k]) continue;
      const double u = n.image[r][k].dot(dir);
      if (u < e.lo) e.lo = u, e.ends[0] = n.point[r][k];
      if (u > e.hi) e.hi = u, e.ends[1] = n.point[r][k];
    }
  return e;
}

}  // namespace

BandProfile bracelet_band_profile(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                                  const RegistrationParams& params, const Vec2& across_px, int samples_per_rim) {
  BandNearSide n;
  if (!band_near_side(X_WH, hand_width_m, camera, params, samples_per_rim, &n)) return BandProfile{};
  const NearSideExtent e = near_side_extent(n, across_px);
  if (!(e.hi > e.lo)) return BandProfile{};
  const NearSideMoments m = near_side_moments(n);
  BandProfile out;
  out.ends = e.ends;
  out.lo_px = e.lo;
  out.hi_px = e.hi;
  out.area_px = m.area;
  out.centroid_px = m.area > 0 ? m.first.dot(across_px) / m.area : 0.5 * (e.lo + e.hi);
  return out;
}

std::optional<Vec2> bracelet_midpoint_px(const Pose& X_WF, double hand_width_m, const vision::Camera& camera,
                                         const RegistrationParams& params, int samples_per_rim) {
  BandNearSide n;
  if (!band_near_side(X_WF, hand_width_m, camera, params, samples_per_rim, &n)) return std::nullopt;
  const NearSideMoments m = near_side_moments(n);
  if (!(m.area > 1e-9)) return std::nullopt;
  const Vec2 c = m.first / m.area;
  // The major axis, as the detector takes it from the red pixels' moments.
  const Vec2 axis = vision::major_axis(m.second / m.area - c * c.transpose());
  const NearSideExtent e = near_side_extent(n, axis);
  if (!(e.hi > e.lo)) return std::nullopt;
  const Vec2 out = c + (0.5 * (e.lo + e.hi) - c.dot(axis)) * axis;
  if (!out.allFinite()) return std::nullopt;
  return out;
}

double bracelet_band_thickness(const Pose& X_WH, double hand_width_m, const vision::Camera& camera,
                               const RegistrationParams& params, const Vec2& across_px,
                               std::array<Vec3, 2>* ends) {
  const BandProfile b = bracelet_band_profile(X_WH, hand_width_m, camera, params, across_px);
  if (!(b.hi_px > b.lo_px)) return 0.0;
  if (ends) *ends = b.ends;
  return b.hi_px - b.lo_px;
}

namespace {

/// The wrist terms' frozen targets (FrozenTargets' wrist, band and thickness parts) at pose q
/// (PoseState s), when the bracelet was detected.
void freeze_wrist(const ResidualProblem& pr, const hand::HandParams& q, const detail::PoseState& s,
                  const vision::Camera& camera, FrozenTargets* tg) {
  const HandObservation& obs = *pr.observation;
  const Pose X_WH = hand::hand_pose(q);
  const double width = pr.model->shape.dimensions.width;
  Vec3 p = bracelet_visible_point(X_WH, width, camera.X_WC().p, *pr.params, &tg->bracelet_shift_W, obs.forearm_H);
  tg->wrist_active = camera.depth(p) >= detail::kMinImageDepth;
  if (!tg->wrist_active) return;
  if (pr.params->bracelet_detector_midpoint) {
    // The point at the visible point's depth that projects where the detector would put the
    // band's midpoint: the shift, frozen, moves it with the band's centre.
    const Pose X_WF = hand::forearm_pose(X_WH, X_WH.R * obs.forearm_H);
    if (const auto m = bracelet_midpoint_px(X_WF, width, camera, *pr.params)) {
      const Vec3 centre = p - tg->bracelet_shift_W;
      p = camera.unproject(*m, camera.depth(p));
      tg->bracelet_shift_W = p - centre;
    }
  }
  if (pr.params->bracelet_length_sigma > 0 && std::isfinite(obs.wrist_length_px) && obs.wrist_length_px > 0) {
    const auto ends = bracelet_band_ends(X_WH, width, camera.X_WC().p, *pr.params);
    tg->band_active =
        camera.depth(ends[0]) >= detail::kMinImageDepth && camera.depth(ends[1]) >= detail::kMinImageDepth;
    // Right-hand H coordinates (PoseState::A maps them to world), so that rigid_point moves them.
    for (std::size_t k = 0; k < 2; ++k) tg->band_end_H[k] = s.A.transpose() * (ends[k] - s.p_W_wrist);
  }
  const Vec2& axis = obs.wrist_axis_px;
  if (pr.params->bracelet_thickness_sigma > 0 && std::isfinite(obs.wrist_thickness_px) &&
      obs.wrist_thickness_px > 0 && axis.allFinite() && std::abs(axis.squaredNorm() - 1.0) < 1e-6) {
    const Vec2 across(-axis.y(), axis.x());
    std::array<Vec3, 2> ends;
    if (bracelet_band_thickness(X_WH, width, camera, *pr.params, across, &ends) > 0) {
      tg->thickness_active = true;
      tg->thickness_dir_px = across;
      for (std::size_t k = 0; k < 2; ++k) tg->thickness_end_H[k] = s.A.transpose() * (ends[k] - s.p_W_wrist);
    }
  }
}

}  // namespace

void freeze_targets(const ResidualProblem& pr, const hand::HandParams& q, FrozenTargets* tg) {
  tg->wrist_active = false;
  tg->band_active = false;
  tg->thickness_active = false;
  for (JointBall& b : tg->balls) b = JointBall{};
  tg->silhouette_count = 0;
  tg->coverage_count = 0;
  tg->axis_count = 0;
  const ImageEvidence* image = pr.image;
  if (!image || !image->camera) return;
  const vision::Camera& camera = *image->camera;
  detail::PoseState s;
  detail::pose_state(*pr.model, q, false, &s);
  tg->bracelet_shift_W = Vec3::Zero();
  if (detail::wrist_observed(*pr.observation)) freeze_wrist(pr, q, s, camera, tg);
  if (!image->alpha.empty() && (image->alpha.type() == CV_32FC1 || image->alpha.type() == CV_8UC1)) {
    joint_ball_targets(*pr.model, s.points, camera, image->alpha, *pr.params, &tg->balls);
    if (pr.params->silhouette_term && pr.params->digit_axis_sigma_px > 0)
      freeze_digit_axes(pr, s, camera, image->alpha, tg);
  }
  if (pr.params->silhouette_term && pr.params->silhouette_inward && image->distance &&
      !image->distance->empty) {
    freeze_silhouette(pr, s, camera, *image->distance, tg);
  }
  if (pr.params->silhouette_term && image->coverage) freeze_coverage(pr, q, camera, *image->coverage, tg);
}

TermCosts term_costs(const ResidualProblem& pr, const FrozenTargets& tg, const hand::HandParams& q) {
  detail::PoseState s;
  detail::pose_state(*pr.model, q, false, &s);
  detail::CostSink sink;
  detail::visit_residuals<false>(pr, tg, q, s, sink);
  return sink.costs;
}

void stacked_residuals(const ResidualProblem& pr, const FrozenTargets& tg,
                       const hand::HandParams& q, VecX* r, MatX* J, std::vector<ResidualTerm>* terms) {
  detail::PoseState s;
  detail::pose_state(*pr.model, q, J != nullptr, &s);
  StackSink sink;
  if (J) {
    detail::visit_residuals<true>(pr, tg, q, s, sink);
  } else {
    detail::visit_residuals<false>(pr, tg, q, s, sink);
  }
  const auto rows = static_cast<Eigen::Index>(sink.r.size());
  r->resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) (*r)[i] = sink.r[static_cast<std::size_t>(i)];
  if (J) {
    J->resize(rows, hand::kParamCount);
    for (Eigen::Index i = 0; i < rows; ++i) J->row(i) = sink.J[static_cast<std::size_t>(i)];
  }
  if (terms) *terms = std::move(sink.terms);
}

std::vector<DigitAxisPoint> digit_sections(const hand::HandModel& model, const hand::HandParams& q,
                                           const vision::Camera& camera, const cv::Mat& alpha,
                                           double threshold) {
  std::array<DigitAxisPoint, kMaxDigitAxisPoints> buffer;
  if (alpha.empty() || (alpha.type() != CV_32FC1 && alpha.type() != CV_8UC1) || !q.q.allFinite()) return {};
  detail::PoseState s;
  detail::pose_state(model, q, false, &s);
  const int n = sections_of(model, s, camera, alpha, threshold, buffer);
  return {buffer.begin(), buffer.begin() + n};
}

namespace detail {

// residual_terms.hpp.
std::optional<double> edge_along(const cv::Mat& alpha, const Vec2& from, const Vec2& dir, double max_px,
                                 double threshold) {
  for (double s = 1.0; s <= max_px; s += 1.0) {
    if (vision::sample_nearest(alpha, from + s * dir) >= threshold) continue;
    const double a0 = vision::sample_bilinear(alpha, from + (s - 1.0) * dir);
    const double a1 = vision::sample_bilinear(alpha, from + s * dir);
    const double f = a0 > a1 ? (a0 - threshold) / (a0 - a1) : 0.5;
    return s - 1.0 + std::clamp(f, 0.0, 1.0);
  }
  return std::nullopt;
}

}  // namespace detail

}  // namespace spidar::registration
