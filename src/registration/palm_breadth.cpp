#include "spidar/registration/palm_breadth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_set>

#include "residual_terms.hpp"

namespace spidar::registration {
namespace {

/// Samples of the palm's cross-section.
constexpr int kSectionSamples = 32;
/// Step of the walk along the chord [px].
constexpr double kWalkStepPx = 0.5;

/// The palm's level `at` in right-hand H coordinates: its centre there [m].
Vec3 palm_level_H(const hand::PalmBox& box, double at) {
  const double y = box.p_H_centre.y() - box.half_extents.y() + 2.0 * at * box.half_extents.y();
  return Vec3(box.p_H_centre.x(), y, box.p_H_centre.z());
}

/// Extent of the cross-section at `at` along `across`: [lo, hi] of its projections' offsets from
/// the level's projected centre [px]; false when a point is behind the camera.
bool section_extent(const hand::HandModel& model, const detail::PoseState& s, const vision::Camera& camera,
                    double at, const Vec2& across, double* lo, double* hi) {
  const hand::PalmBox& box = model.shape.palm;
  const Vec3 c_H = palm_level_H(box, at);
  const Vec3 c_W = detail::rigid_point(s, c_H, nullptr);
  if (!(camera.depth(c_W) >= detail::kMinImageDepth)) return false;
  const Vec2 c_px = camera.project(c_W);
  *lo = std::numeric_limits<double>::infinity();
  *hi = -*lo;
  // A stadium: the breadth's straight part, with half circles of the half thickness at the edges.
  const double r = std::min(box.half_extents.z(), box.half_extents.x());
  const double straight = box.half_extents.x() - r;
  for (int i = 0; i < kSectionSamples; ++i) {
    const double phi = 2.0 * std::numbers::pi * (i + 0.5) / kSectionSamples;
    const double x = (std::cos(phi) >= 0 ? straight : -straight) + r * std::cos(phi);
    const Vec3 p_H = c_H + Vec3(x, 0.0, r * std::sin(phi));
    const Vec3 p_W = detail::rigid_point(s, p_H, nullptr);
    if (!(camera.depth(p_W) >= detail::kMinImageDepth)) return false;
    const double o = (camera.project(p_W) - c_px).dot(across);
    *lo = std::min(*lo, o);
    *hi = std::max(*hi, o);
  }
  return std::isfinite(*lo) && std::isfinite(*hi);
}

}  // namespace

double model_palm_chord_px(const hand::HandModel& model, const hand::HandParams& q,
                           const vision::Camera& camera, double at, const Vec2& across) {
  detail::PoseState s;
  detail::pose_state(model, q, false, &s);
  double lo = 0, hi = 0;
  if (!section_extent(model, s, camera, at, across, &lo, &hi)) return 0.0;
  return hi - lo;
}

std::optional<PalmChord> measure_palm_chord(const hand::HandModel& model, const hand::HandParams& q,
                                            const vision::Camera& camera, const cv::Mat& silhouette,
                                            const std::vector<OwnedPixel>* owned, int owned_stride_px,
                                            const PalmChordParams& params) {
  if (silhouette.empty() || silhouette.type() != CV_8UC1 || !q.q.allFinite()) return std::nullopt;
  if (!(params.at >= 0.0 && params.at <= 1.0)) return std::nullopt;
  detail::PoseState s;
  detail::pose_state(model, q, false, &s);
  const hand::PalmBox& box = model.shape.palm;
  const Vec3 c_W = detail::rigid_point(s, palm_level_H(box, params.at), nullptr);
  if (!(camera.depth(c_W) >= detail::kMinImageDepth)) return std::nullopt;
  // Face on: the palm's normal along the ray to its centre.
  const Vec3 n_W = s.A.col(2);
  const Vec3 ray = (c_W - camera.X_WC().p).normalized();
  if (!(std::abs(n_W.dot(ray)) >= params.min_facing)) return std::nullopt;
  // Across the palm's projected long axis.
  const Vec2 c_px = camera.project(c_W);
  const Vec2 along = camera.project(c_W + 0.01 * s.A.col(1)) - c_px;
  if (!(along.norm() > 1e-6) || !c_px.allFinite()) return std::nullopt;
  const Vec2 across = Vec2(-along.y(), along.x()).normalized();
  double lo = 0, hi = 0;
  if (!section_extent(model, s, camera, params.at, across, &lo, &hi)) return std::nullopt;
  const double model_px = hi - lo;
  if (!(model_px > 2.0)) return std::nullopt;

  auto on = [&](const Vec2& p, bool* inside) {
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    *inside = x >= 0 && y >= 0 && x < silhouette.cols && y < silhouette.rows;
    return *inside && silhouette.at<std::uint8_t>(y, x) != 0;
  };
  bool inside = false;
  if (!on(c_px, &inside)) return std::nullopt;
  // Walk out both ways; the chord ends at the last silhouette sample before the first one off it.
  const double max_px = (1.0 + params.max_relative_change) * model_px + 4.0;
  std::array<double, 2> end{};  // [−across, +across] distances from the centre [px]
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    double d = 0.0;
    for (;;) {
      const double next = d + kWalkStepPx;
      if (next > max_px) return std::nullopt;  // no end: merged with something else
      if (!on(c_px + sign * next * across, &inside)) {
        if (!inside) return std::nullopt;  // the line leaves the image
        break;
      }
      d = next;
    }
    end[side] = d;
  }
  const double measured = end[0] + end[1];
  if (!(std::abs(measured / model_px - 1.0) <= params.max_relative_change)) return std::nullopt;

  // A digit drawn at the pose covering the line beyond the model palm's edges, where the chord
  // reached: the chord would be the palm's and the digit's. (A finger's proximal phalanx ends flush
  // with the palm's edge at its knuckle: only what lies a clearance beyond the edge counts.)
  ProjectedHand ph;
  project_hand(model, q, camera, 0.0, &ph);
  const std::array<double, 2> model_edge{-lo, hi};
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    for (double d = model_edge[side] + params.digit_clearance_px; d <= end[side] + params.digit_clearance_px;
         d += 1.0) {
      const Vec2 p = c_px + sign * d * across;
      for (int bone = 0; bone < kSilhouetteBoneCount; ++bone) {
        const BoneRef b = silhouette_bone(bone);
        if (b.finger != hand::kThumb && b.segment == 0) continue;  // a metacarpal: inside the palm
        if (capsule_distance(ph.bones[bone], p) < 0.0) return std::nullopt;
      }
    }
  }
  // Pixels on the chord that the other hand or a forearm owns.
  if (owned != nullptr) {
    const int st = std::max(owned_stride_px, 1);
    std::unordered_set<long long> mine;
    mine.reserve(owned->size() * 2);
    auto key = [](int x, int y) { return (static_cast<long long>(y) << 32) | static_cast<unsigned>(x); };
    for (const OwnedPixel& o : *owned)
      mine.insert(key(static_cast<int>(std::lround(o.px.x())), static_cast<int>(std::lround(o.px.y()))));
    auto node = [&](double v) {
      return st / 2 + static_cast<int>(std::lround((v - st / 2) / st)) * st;
    };
    for (double d = -end[0]; d <= end[1]; d += 1.0) {
      const Vec2 p = c_px + d * across;
      const int gx = node(p.x()), gy = node(p.y());
      if (gx < 0 || gy < 0 || gx >= silhouette.cols || gy >= silhouette.rows) continue;
      if (silhouette.at<std::uint8_t>(gy, gx) != 0 && !mine.contains(key(gx, gy))) return std::nullopt;
    }
  }
  PalmChord chord;
  chord.at = params.at;
  chord.across_px = across;
  chord.measured_px = measured;
  return chord;
}

}  // namespace spidar::registration
