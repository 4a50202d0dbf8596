#include "spidar/registration/wrist_depth.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::registration {

std::optional<hand::HandParams> other_wrist_depth(const hand::HandModel& model, const hand::HandParams& q,
                                                  const HandObservation& obs, const vision::Camera& camera,
                                                  double min_separation_m) {
  if (!obs.wrist_px || !obs.wrist_px->allFinite() || !q.q.allFinite()) return std::nullopt;
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  Vec3 c = Vec3::Zero();
  int n = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    if (!obs.fingertip_valid[f] || !obs.p_W_fingertip[f].allFinite()) continue;
    c += pts.p_W_fingertip[f];
    ++n;
  }
  if (n < 3) return std::nullopt;
  c /= n;
  const Vec3 w = q.p_W_wrist();
  const double d = (w - c).norm();
  // The ray o + t·u, ‖u‖ = 1, meets the sphere ‖x − c‖ = d where t² + 2t·u·(o − c) + ‖o − c‖² − d² = 0.
  const Vec3 o = camera.X_WC().p;
  const Vec3 u = camera.ray_direction_W(*obs.wrist_px);
  const double b = u.dot(o - c);
  const double disc = b * b - ((o - c).squaredNorm() - d * d);
  if (!(disc > 0) || !u.allFinite()) return std::nullopt;
  const double root = std::sqrt(disc);
  const double t_near = -b - root, t_far = -b + root;
  if (2 * root < min_separation_m || t_near <= 0) return std::nullopt;
  // The root the wrist is not at: compare with where the wrist's own depth along the ray is.
  const double t_now = (w - o).dot(u);
  const double t_other = std::abs(t_now - t_near) < std::abs(t_now - t_far) ? t_far : t_near;
  const Vec3 w_other = o + t_other * u;
  const Quat turn = Quat::FromTwoVectors(w - c, w_other - c);
  hand::HandParams out = q;
  const Eigen::AngleAxisd aa(Mat3(turn.toRotationMatrix() * hand::rotation_from_vector(q.r_W_hand())));
  out.set_wrist(c + turn * (w - c), aa.angle() * aa.axis());
  if (!out.q.allFinite()) return std::nullopt;
  return out;
}

}  // namespace spidar::registration
