#include "spidar/device/fingertip_impedance.hpp"

#include <algorithm>
#include <cmath>

namespace spidar::device {

FingertipHold sanitized(const FingertipHold& hold) {
  if (!hold.R_WE.allFinite() || !hold.scale.allFinite()) return {};
  FingertipHold h = hold;
  for (int i = 0; i < 3; ++i) h.scale[i] = std::clamp(h.scale[i], 1.0, kMaxHoldScale);
  return h;
}

void step_fingertip(const FingertipImpedance& imp, const FingertipHold& hold, const Vec3& p_W_goal,
                    const Vec3& f_W, double dt, Vec3& p_W, Vec3& v_W) {
  // In the principal frame E the spring and the damper are diagonal.
  const Vec3 e_E = hold.R_WE.transpose() * (p_W_goal - p_W);
  const Vec3 v_E = hold.R_WE.transpose() * v_W;
  Vec3 f_E;
  for (int i = 0; i < 3; ++i) {
    const double held = std::clamp(e_E[i], -imp.hold_range, imp.hold_range);
    f_E[i] = imp.stiffness * (e_E[i] + (hold.scale[i] - 1.0) * held) -
             imp.damping * std::sqrt(hold.scale[i]) * v_E[i];
  }
  const Vec3 a_W = (hold.R_WE * f_E + f_W) / imp.mass;
  v_W += a_W * dt;  // semi-implicit Euler
  p_W += v_W * dt;
}

}  // namespace spidar::device
