#include "spidar/registration/joint_balls.hpp"

#include <cmath>

#include "spidar/vision/silhouette.hpp"

namespace spidar::registration {
namespace {

/// Joints nearer the camera plane than this [m] get no ball (their projection is meaningless).
constexpr double kMinBallDepth = 0.01;

}  // namespace

Vec2 joint_ball_target(const cv::Mat& alpha, const Vec2& centre_px, const Vec2& bone_dir_px,
                       double radius_px, double gain, double threshold, int* on_count) {
  // Neighbours: two along the bone (±d) and two across it (±n), at the ball's radius. A zero
  // direction means "axis aligned": ±x and ±y.
  Vec2 along = bone_dir_px;
  const double len = along.norm();
  along = len > 1e-9 ? Vec2(along / len) : Vec2(1.0, 0.0);
  const Vec2 across(-along.y(), along.x());
  const std::array<Vec2, 4> offsets{radius_px * along, -radius_px * along, radius_px * across,
                                    -radius_px * across};
  Vec2 sum = Vec2::Zero();
  int on = 0;
  for (const Vec2& o : offsets) {
    if (vision::on_silhouette(alpha, centre_px + o, threshold)) {
      sum += o;  // τ_i (P_i − P)
      ++on;
    }
  }
  if (on_count) *on_count = on;
  return centre_px + gain * sum;
}

void joint_ball_targets(const hand::HandModel& model, const hand::HandPoints& points,
                        const vision::Camera& camera, const cv::Mat& alpha,
                        const RegistrationParams& params, JointBalls* balls) {
  for (JointBall& b : *balls) b = JointBall{};
  if (alpha.empty()) return;
  const double focal = 0.5 * (camera.intrinsics().fx + camera.intrinsics().fy);
  // Balls at MCP, PIP and DIP of every finger (the little finger too: it copies the ring
  // finger's parameters, so its image pulls on them) and at the thumb's CMC, MCP and IP.
  // None at the wrist (the bracelet term holds it, and the forearm continues the silhouette)
  // nor at the tips (their "along" neighbour lies beyond the end of the finger, off the
  // silhouette by construction, so eq. 21 would always pull a tip back toward its middle
  // phalanx).
  for (int f = 0; f < hand::kFingerCount; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int j = hand::joint_index(f, k);
      const Vec3& p = points.p_W_joint[j];
      const double depth = camera.depth(p);
      if (!(depth >= kMinBallDepth) || !p.allFinite()) continue;
      const Vec2 uv = camera.project(p);
      if (!camera.in_image(uv)) continue;
      // The projected direction of the bone leaving the joint.
      const Vec3& p_next = points.p_W_joint[hand::joint_index(f, k + 1)];
      Vec2 dir = Vec2::Zero();
      if (camera.depth(p_next) >= kMinBallDepth) {
        dir = camera.project(p_next) - uv;
        const double n = dir.norm();
        dir = n > 1e-9 ? Vec2(dir / n) : Vec2::Zero();
      }
      // The bone leaving joint k: segment k for the thumb (CMC → metacarpal), k + 1 for the
      // fingers (segment 0 is the metacarpal, which ends at the MCP).
      const int segment = f == hand::kThumb ? k : k + 1;
      const double radius_px =
          params.ball_radius_scale * model.shape.digits[f].radius[segment] * focal / depth;
      JointBall& b = (*balls)[j];
      b.used = true;
      b.centre_px = uv;
      b.radius_px = radius_px;
      b.target_px = joint_ball_target(alpha, uv, dir, radius_px, params.joint_ball_alpha,
                                      params.matte_threshold, &b.on_count);
    }
  }
}

}  // namespace spidar::registration
