#include "spidar/registration/fingertip_end.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "spidar/hand/kinematics.hpp"
#include "spidar/vision/silhouette.hpp"

#include "residual_terms.hpp"

namespace spidar::registration {
namespace {

/// The silhouette bone (residuals.hpp) of digit f's distal phalanx.
int distal_bone(int f) { return f == hand::kThumb ? 2 : 3 + 4 * (f - 1) + 3; }

/// The distal phalanx's radius in the model [m] (hand_shape.hpp: the thumb's is its segment 2).
double distal_radius(const hand::HandModel& model, int f) {
  return model.shape.digits[f].radius[f == hand::kThumb ? 2 : 3];
}

/// s ≥ 0 [m] along the 3D line c + s·a whose projection lies `e_px` along `dir_px` from c's
/// projection `u0` (bisection; the projection along the line is monotone for a line within
/// max_tilt of the image plane over these few centimetres).
double back_onto_axis(const vision::Camera& camera, const Vec3& c, const Vec3& a, const Vec2& u0,
                      const Vec2& dir_px, double e_px, double s_max) {
  double lo = 0.0, hi = s_max;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    const Vec2 u = camera.project(c + mid * a);
    if ((u - u0).dot(dir_px) < e_px) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

std::vector<FingertipEnd> fingertip_ends(const hand::HandModel& model, const hand::HandParams& q,
                                         const HandObservation& observation, const vision::Camera& camera,
                                         const cv::Mat& alpha, double threshold,
                                         const FingertipEndParams& params, const ProjectedHand* outline) {
  std::vector<FingertipEnd> out;
  if (alpha.empty() || (alpha.type() != CV_32FC1 && alpha.type() != CV_8UC1) || !q.q.allFinite()) return out;
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  const Vec3 eye = camera.X_WC().p;
  for (int f = params.thumb ? hand::kThumb : hand::kIndex; f < hand::kFingertipCount; ++f) {
    if (!observation.fingertip_valid[f]) continue;
    const Vec3& cap = observation.p_W_fingertip[f];
    if (!cap.allFinite() || (pts.p_W_fingertip[f] - cap).norm() > params.max_cap_miss_m) continue;
    const Vec3 dip = pts.p_W_joint[hand::joint_index(f, 2)], tip = pts.p_W_joint[hand::joint_index(f, 3)];
    if (!((tip - dip).norm() > 1e-6)) continue;
    const Vec3 a = (tip - dip).normalized();
    // The axis's angle out of the image plane: its component along the ray to the cap.
    const Vec3 ray = cap - eye;
    if (!(camera.depth(cap) >= detail::kMinImageDepth) || !(ray.norm() > 1e-6)) continue;
    const double along_ray = std::abs(a.dot(ray.normalized()));
    const double tilt = std::asin(std::min(along_ray, 1.0));
    if (!(tilt <= params.max_tilt_rad)) continue;
    const Vec2 u0 = camera.project(cap);
    if (!camera.in_image(u0) || !vision::on_silhouette(alpha, u0, threshold)) continue;
    const Vec3 far = cap + params.max_reach_m * a;
    if (!(camera.depth(far) >= detail::kMinImageDepth)) continue;
    const Vec2 u_far = camera.project(far);
    const Vec2 d = u_far - u0;
    if (!(d.norm() > 2.0)) continue;  // too small in the image to measure
    const Vec2 dir = d.normalized();
    const auto e_px = detail::edge_along(alpha, u0, dir, d.norm(), threshold);
    if (!e_px) continue;  // runs on past the largest reach (another finger, the other hand) or out
    const Vec2 end = u0 + *e_px * dir;
    if (!camera.in_image(end)) continue;
    const double rho = distal_radius(model, f);
    if (outline) {
      // Every pixel of the walk outside the other parts (the distal phalanx's own and the middle
      // one's, which the cap lies next to, aside), and its end by min_clearance_px.
      auto outside = [&](const Vec2& u, double margin) {
        for (int part = -1; part < kSilhouetteBoneCount; ++part)
          if (part != distal_bone(f) && part != distal_bone(f) - 1 && part_distance(*outline, part, u) < margin)
            return false;
        return true;
      };
      // The walk from where the model's own fingertip begins to round off (its reach less the
      // distal radius): nearer the cap a neighbour lying alongside may overlap it in the image.
      const double from_m = std::max(0.0, model_fingertip_reach_m(model) - rho);
      const double from_px = (camera.project(cap + from_m * a) - u0).dot(dir);
      bool clear = outside(end, params.min_clearance_px);
      for (double t = std::max(from_px, 0.0); clear && t < *e_px; t += 1.0)
        clear = outside(u0 + t * dir, -params.max_overlap_px);
      if (!clear) continue;
    }
    const double s = back_onto_axis(camera, cap, a, u0, dir, *e_px, params.max_reach_m);
    // The rounded end seen tilted reaches ρ (1/cos φ − 1) beyond the axis's end in the image.
    const double reach = s - rho * (1.0 / std::cos(tilt) - 1.0);
    if (!(reach >= params.min_reach_m && reach <= params.max_reach_m)) continue;
    out.push_back(FingertipEnd{f, reach, tilt, u0, end});
  }
  return out;
}

}  // namespace spidar::registration
