#include "spidar/session/interactive_hands.hpp"

#include <algorithm>
#include <cmath>

#include "spidar/core/units.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::session {
namespace {

Vec3 rotation_vector(const Mat3& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

}  // namespace

InteractiveHands::InteractiveHands(const std::array<hand::HandModel, 2>& truth,
                                   const std::array<hand::HandParams, 2>& open,
                                   const std::array<hand::HandParams, 2>& closed)
    : truth_(truth), open_(open), closed_(closed) {
  controls_.publish(HandControls{});
}

void InteractiveHands::set(const HandControls& c) {
  HandControls k = c;
  for (HandControl& h : k) {
    for (double& v : h.offset_W) v = std::isfinite(v) ? std::clamp(v, -0.25, 0.25) : 0.0;
    h.yaw = std::isfinite(h.yaw) ? std::clamp(h.yaw, -units::kPi, units::kPi) : 0.0;
    h.closeness = std::isfinite(h.closeness) ? std::clamp(h.closeness, 0.0, 1.0) : 0.0;
  }
  controls_.publish(k);
}

HandControls InteractiveHands::controls() const { return controls_.read().value_or(HandControls{}); }

std::array<hand::HandParams, 2> InteractiveHands::pose(const HandControls& c) const {
  std::array<hand::HandParams, 2> out = open_;
  for (int h = 0; h < 2; ++h) {
    const HandControl& k = c[h];
    hand::HandParams& q = out[h];
    for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i)
      q.q[i] = open_[h].q[i] + k.closeness * (closed_[h].q[i] - open_[h].q[i]);
    // Yaw about the vertical through the wrist, then the displacement.
    const Mat3 R_yaw = Eigen::AngleAxisd(k.yaw, Vec3::UnitZ()).toRotationMatrix();
    const Mat3 R = R_yaw * hand::rotation_from_vector(open_[h].r_W_hand());
    q.set_wrist(open_[h].p_W_wrist() + Vec3(k.offset_W[0], k.offset_W[1], k.offset_W[2]),
                rotation_vector(R));
  }
  return out;
}

void InteractiveHands::goals(double /*t_s*/, std::span<Vec3> p_W_goal) {
  const auto q = pose(controls());
  for (int h = 0; h < 2; ++h) {
    const hand::HandPoints pts = hand::forward_kinematics(truth_[h], q[h]);
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      const std::size_t i = static_cast<std::size_t>(4 * h + f);
      if (i < p_W_goal.size()) p_W_goal[i] = pts.p_W_fingertip[f];
    }
  }
}

}  // namespace spidar::session
