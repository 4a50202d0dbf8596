#include "spidar/sim/scripted_grasp.hpp"
#include "smooth_ramp.hpp"

#include <algorithm>
#include <cmath>

namespace spidar::sim {
namespace {

Vec3 rotz(const Vec3& v, double a) {
  return {std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y(), v.z()};
}

}  // namespace

const char* RubiksScript::phase(double t) {
  if (t < 1.0) return "approach";
  if (t < 2.0) return "grasp";
  if (t < 3.0) return "lift";
  if (t < 5.5) return "turn top layer";
  if (t < 6.5) return "right hand lets go";
  if (t < 7.5) return "set down, open";
  return "done";
}

void RubiksScript::goals(double t, std::span<Vec3> goal) {
  const double h = p_.half, r = p_.proxy_radius, s = p_.squeeze, a = p_.pitch;
  const double face = h + r - s;  // goal distance of a pressing fingertip from the cube's axis
  // Contact offsets from the cube centre (cube frame = world axes at the start).
  // Left hand on the two lower layers: thumb in front (−y), fingers behind (+y).
  const Vec3 left[4] = {Vec3(-0.012, -face, -0.45 * a), Vec3(-0.016, face, -0.2 * a),
                        Vec3(-0.006, face, -0.7 * a), Vec3(-0.020, face, -0.9 * a)};
  // Right hand on the top layer: thumb in front, index and ring behind, middle on top.
  const Vec3 right[4] = {Vec3(0.006, -face, a), Vec3(0.002, face, a), Vec3(0.004, 0.004, h + r - 0.6 * s),
                         Vec3(0.012, face, a)};
  // Open hands: 3.5 cm out along each contact's push direction, and up a little.
  auto opened = [&](const Vec3& c) {
    Vec3 out = c;
    if (std::abs(c.y()) >= face - 1e-9) out.y() += (c.y() > 0 ? 1 : -1) * 0.035;
    else out.z() += 0.035;
    return Vec3(out + Vec3(0, 0, 0.01));
  };
  const double close = ramp(t, 1.0, 2.0);
  const double lift = p_.lift * (ramp(t, 2.0, 3.0) - ramp(t, 6.5, 7.2));
  const double turn = p_.turn * ramp(t, 3.0, 5.5);
  const double release_right = ramp(t, 5.5, 6.5);
  const double release_left = ramp(t, 7.0, 7.5);
  const double approach = ramp(t, 0.0, 1.0);
  for (int f = 0; f < 8 && f < static_cast<int>(goal.size()); ++f) {
    const bool is_right = f >= 4;
    const Vec3 contact = is_right ? right[f - 4] : left[f];
    const Vec3 open = opened(contact);
    const Vec3 far = open + Vec3(is_right ? 0.04 : -0.04, 0, 0.03);  // where the hands start
    Vec3 p = far + (open - far) * approach;
    p += (contact - open) * close;
    if (is_right) {
      p = rotz(p, turn);
      p += (rotz(open, turn) - rotz(contact, turn)) * release_right;
    } else {
      p += (open - contact) * release_left;
    }
    goal[f] = p_.p_W_cube + p + Vec3(0, 0, lift);
  }
}

}  // namespace spidar::sim
