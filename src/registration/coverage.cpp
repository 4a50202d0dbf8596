#include "spidar/registration/coverage.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/types.hpp>

#include "residual_terms.hpp"

namespace spidar::registration {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// The forearm capsule's length from the wrist joint toward the elbow [m].
constexpr double kForearmLengthM = 0.25;

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

ImageCapsule project_capsule(const vision::Camera& camera, const Vec3& a, const Vec3& c,
                             double radius_m, double focal) {
  ImageCapsule k;
  const double da = camera.depth(a), dc = camera.depth(c);
  if (!(da >= detail::kMinImageDepth) || !(dc >= detail::kMinImageDepth)) return k;
  k.a = camera.project(a);
  k.c = camera.project(c);
  k.ra = radius_m * focal / da;
  k.rc = radius_m * focal / dc;
  k.valid = k.a.allFinite() && k.c.allFinite();
  return k;
}

/// Convex hull of the palm's projected corners (Andrew's monotone chain), counter-clockwise in
/// image coordinates (positive cross product turns).
void palm_hull(ProjectedHand* h) {
  std::array<int, 8> idx{};
  for (int i = 0; i < 8; ++i) idx[i] = i;
  const auto& p = h->palm_px;
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return p[a].x() < p[b].x() || (p[a].x() == p[b].x() && p[a].y() < p[b].y());
  });
  std::array<int, 16> out{};
  int k = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const int start = k;
    for (int n = 0; n < 8; ++n) {
      const int i = pass == 0 ? idx[n] : idx[7 - n];
      while (k >= start + 2 && cross2(p[out[k - 1]] - p[out[k - 2]], p[i] - p[out[k - 1]]) <= 0) --k;
      out[k++] = i;
    }
    --k;  // the last point of each chain starts the other
  }
  h->hull_count = std::min(k, 8);
  for (int i = 0; i < h->hull_count; ++i) h->hull[i] = out[i];
  if (h->hull_count < 3) h->hull_count = 0;
}

}  // namespace

double capsule_distance(const ImageCapsule& c, const Vec2& px, double* t_out) {
  if (!c.valid) return kInf;
  const Vec2 d = c.c - c.a;
  const double len2 = d.squaredNorm();
  double t = len2 > 1e-12 ? (px - c.a).dot(d) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  if (t_out) *t_out = t;
  return (px - (c.a + t * d)).norm() - (c.ra + t * (c.rc - c.ra));
}

void project_hand(const hand::HandModel& model, const hand::HandParams& q,
                  const vision::Camera& camera, double forearm_radius_m, ProjectedHand* out,
                  const Vec3& forearm_H) {
  detail::PoseState s;
  detail::pose_state(model, q, false, &s);
  const double focal = 0.5 * (camera.intrinsics().fx + camera.intrinsics().fy);
  for (int bone = 0; bone < kSilhouetteBoneCount; ++bone) {
    const BoneRef b = silhouette_bone(bone);
    const Vec3 a = detail::bone_end(model, s, b, 0, nullptr);
    const Vec3 c = detail::bone_end(model, s, b, 1, nullptr);
    out->bones[bone] = project_capsule(camera, a, c, model.shape.digits[b.finger].radius[b.segment], focal);
  }
  const hand::PalmBox& box = model.shape.palm;
  out->hull_count = 0;
  bool palm_visible = true;
  for (int i = 0; i < 8; ++i) {
    const Vec3 sign((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
    out->palm_H[i] = box.p_H_centre + sign.cwiseProduct(box.half_extents);
    const Vec3 p = detail::rigid_point(s, out->palm_H[i], nullptr);
    palm_visible = palm_visible && camera.depth(p) >= detail::kMinImageDepth;
    out->palm_px[i] = camera.project(p);
    palm_visible = palm_visible && out->palm_px[i].allFinite();
  }
  if (palm_visible) palm_hull(out);
  out->forearm = project_capsule(camera, s.p_W_wrist,
                                 detail::rigid_point(s, kForearmLengthM * forearm_H, nullptr),
                                 forearm_radius_m, focal);
}

namespace {

/// Signed distance from `px` to the palm hull's boundary [px] (≤ 0 inside: left of every
/// counter-clockwise edge), with the nearest boundary point in the image and on the box (right-hand
/// H) when asked for. +∞ if the palm is not drawn.
double palm_distance(const ProjectedHand& hand, const Vec2& px, Vec2* edge_px = nullptr,
                     Vec3* edge_H = nullptr) {
  if (hand.hull_count < 3) return kInf;
  bool inside = true;
  double edge = kInf;
  for (int k = 0; k < hand.hull_count; ++k) {
    const int i = hand.hull[k], j = hand.hull[(k + 1) % hand.hull_count];
    const Vec2 a = hand.palm_px[i], d = hand.palm_px[j] - a;
    if (cross2(d, px - a) < 0) inside = false;
    const double len2 = d.squaredNorm();
    const double s = len2 > 1e-12 ? std::clamp((px - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    const double dist = (px - (a + s * d)).norm();
    if (dist < edge) {
      edge = dist;
      if (edge_px) *edge_px = a + s * d;
      if (edge_H) *edge_H = (1.0 - s) * hand.palm_H[i] + s * hand.palm_H[j];
    }
  }
  return inside ? -edge : edge;
}

}  // namespace

OutlineNearest nearest_part(const ProjectedHand& hand, const Vec2& px) {
  OutlineNearest best;
  best.distance_px = kInf;
  for (int bone = 0; bone < kSilhouetteBoneCount; ++bone) {
    double t = 0;
    const double d = capsule_distance(hand.bones[bone], px, &t);
    if (d < best.distance_px) {
      best.distance_px = d;
      best.bone = bone;
      best.t = t;
    }
  }
  if (best.bone >= 0) {
    const ImageCapsule& c = hand.bones[best.bone];
    const Vec2 axis = c.a + best.t * (c.c - c.a);
    const Vec2 n = px - axis;
    const double r = c.ra + best.t * (c.rc - c.ra);
    best.edge_px = n.norm() > 1e-9 ? Vec2(axis + r * n.normalized()) : axis;
  }
  Vec2 edge_px = Vec2::Zero();
  Vec3 edge_H = Vec3::Zero();
  const double palm_d = palm_distance(hand, px, &edge_px, &edge_H);
  if (palm_d < best.distance_px) {
    best.distance_px = palm_d;
    best.bone = -1;
    best.t = 0;
    best.edge_px = edge_px;
    best.palm_H = edge_H;
  }
  return best;
}

double part_distance(const ProjectedHand& hand, int part, const Vec2& px) {
  if (part >= 0) return part < kSilhouetteBoneCount ? capsule_distance(hand.bones[part], px) : kInf;
  return palm_distance(hand, px);
}

double section_clearance_px(const ProjectedHand& hand, const DigitAxisPoint& section) {
  double clear = kInf;
  for (const double side : {-1.0, 1.0}) {
    // The section's edges: its midpoint ± half its width across the bone.
    const Vec2 edge = section.target_px + side * 0.5 * section.width_px * section.across_px;
    for (int part = -1; part < kSilhouetteBoneCount; ++part)
      if (part != section.bone) clear = std::min(clear, part_distance(hand, part, edge));
  }
  return clear;
}

void coverage_evidence(const cv::Mat& silhouette, const std::array<const ProjectedHand*, 2>& hands,
                       const RegistrationParams& params, std::array<std::vector<OwnedPixel>, 2>* owned) {
  for (auto& o : *owned) o.clear();
  if (silhouette.empty() || silhouette.type() != CV_8UC1) return;
  const int stride = std::max(params.coverage_stride_px, 1);
  const double max_d = params.coverage_max_px;
  // Each hand's parts' bounding box grown by max_d: a pixel outside it is not that hand's.
  std::array<cv::Rect2d, 2> box{};
  for (int h = 0; h < 2; ++h) {
    if (!hands[h]) continue;
    double x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
    auto grow = [&](const Vec2& p, double r) {
      x0 = std::min(x0, p.x() - r);
      y0 = std::min(y0, p.y() - r);
      x1 = std::max(x1, p.x() + r);
      y1 = std::max(y1, p.y() + r);
    };
    for (const ImageCapsule& c : hands[h]->bones) {
      if (!c.valid) continue;
      grow(c.a, c.ra);
      grow(c.c, c.rc);
    }
    for (int k = 0; k < hands[h]->hull_count; ++k) grow(hands[h]->palm_px[hands[h]->hull[k]], 0.0);
    if (x1 >= x0) box[h] = cv::Rect2d(x0 - max_d, y0 - max_d, x1 - x0 + 2 * max_d, y1 - y0 + 2 * max_d);
  }
  for (int y = stride / 2; y < silhouette.rows; y += stride) {
    const std::uint8_t* row = silhouette.ptr<std::uint8_t>(y);
    for (int x = stride / 2; x < silhouette.cols; x += stride) {
      if (row[x] == 0) continue;
      const Vec2 px(x, y);
      int owner = -1, part = -1;
      double best = kInf;
      for (int h = 0; h < 2; ++h) {
        if (!hands[h] || !box[h].contains(cv::Point2d(x, y))) continue;
        const OutlineNearest n = nearest_part(*hands[h], px);
        if (n.distance_px < best) {
          best = n.distance_px;
          owner = h;
          part = n.bone;
        }
      }
      if (owner < 0 || best > max_d) continue;
      bool forearm = false;
      for (int h = 0; h < 2 && !forearm; ++h)
        forearm = hands[h] && capsule_distance(hands[h]->forearm, px) < best;
      if (!forearm) (*owned)[owner].push_back(OwnedPixel{px, part});
    }
  }
}

}  // namespace spidar::registration
