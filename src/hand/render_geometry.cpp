#include "spidar/hand/render_geometry.hpp"

#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {

HandRenderShapes hand_render_shapes(const HandModel& model, const HandParams& params) {
  return hand_render_shapes(model, params, forward_kinematics(model, params));
}

HandRenderShapes hand_render_shapes(const HandModel& model, const HandParams& params,
                                    const HandPoints& points) {
  const Vec3 p_W_wrist = params.p_W_wrist();
  const Mat3 R_WH = rotation_from_vector(params.r_W_hand());
  Mat3 A = R_WH;  // right-hand H coordinates → world
  if (model.side == Side::kLeft) A.col(0) = -A.col(0);

  HandRenderShapes out;
  out.side = model.side;
  out.capsules.reserve(19);
  for (int f = 0; f < kFingerCount; ++f) {
    const DigitShape& d = model.shape.digits[f];
    const int n = f == kThumb ? 3 : 4;  // segments
    // Segment s runs between two points: fingers base → MCP → PIP → DIP → tip; thumb CMC → MCP
    // → IP → tip.
    std::array<Vec3, 5> p;
    int count = 0;
    if (f != kThumb) p[count++] = p_W_wrist + A * d.p_H_base;
    for (int k = 0; k < 4; ++k) p[count++] = points.p_W_joint[joint_index(f, k)];
    for (int s = 0; s < n; ++s) {
      Capsule c{p[s], p[s + 1], d.radius[s], f, s};
      if (s == n - 1) {
        const Vec3 bone = c.p_W_b - c.p_W_a;
        const double len = bone.norm();
        if (len > c.radius) c.p_W_b -= bone * (c.radius / len);
      }
      out.capsules.push_back(c);
    }
  }
  Box palm;
  palm.X_WB = Pose{Quat(R_WH), p_W_wrist + A * model.shape.palm.p_H_centre};
  palm.half_extents = model.shape.palm.half_extents;
  out.boxes.push_back(palm);
  return out;
}

}  // namespace spidar::hand
