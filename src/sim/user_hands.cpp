#include "spidar/core/units.hpp"
#include "spidar/sim/user_hands.hpp"

#include <cmath>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/joint_limits.hpp"

namespace spidar::sim {

std::array<Vec3, 2> user_elbows(const RubiksTask& task, double forearm_length_m) {
  return {hand::elbow_in_line(task.nominal(0.0, hand::Side::kLeft), forearm_length_m),
          hand::elbow_in_line(task.nominal(0.0, hand::Side::kRight), forearm_length_m)};
}
namespace {

/// Mean distance of the hand's fingertip caps from the observed ones [m] (0 without any).
double mean_cap_distance(const hand::HandModel& model, const hand::HandParams& q,
                         const registration::HandObservation& obs) {
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  double sum = 0;
  int n = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    if (!obs.fingertip_valid[f]) continue;
    sum += (pts.p_W_fingertip[f] - obs.p_W_fingertip[f]).norm();
    ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace

registration::RegistrationParams fingertip_ik_params(const UserHandsParams& p) {
  registration::RegistrationParams r;
  r.fingertip_sigma_m = p.fingertip_sigma_m;
  r.prior_sigma_wrist_m = p.wrist_sigma_m;
  r.prior_sigma_rotation_rad = p.rotation_sigma_rad;
  r.prior_sigma_joint_rad = p.joint_sigma_rad;
  r.max_iterations = p.iterations;
  r.cost_epsilon = 0.0;  // run to the step criterion: ground truth should be tight
  r.step_epsilon = 1e-9;
  r.relative_epsilon = 1e-9;
  return r;
}

UserHands::UserHands(const std::array<hand::HandModel, 2>& truth, const RubiksTask& task,
                     const UserHandsParams& params)
    : truth_(truth), pushed_(truth), task_(task), p_(params), solver_(fingertip_ik_params(params)) {
  for (auto& m : pushed_) m.limits = hand::passive_limits(m.limits, p_.passive);
}

void UserHands::update(double t, std::span<const Vec3> caps) {
  for (int h = 0; h < 2; ++h) {
    const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
    const hand::HandParams nominal = task_.nominal(t, side);
    if (first_) q_[h] = nominal;
    registration::HandObservation obs;
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      const std::size_t k = static_cast<std::size_t>(4 * h + f);
      if (k >= caps.size()) continue;
      obs.p_W_fingertip[f] = caps[k];
      obs.fingertip_valid[f] = caps[k].allFinite();
    }
    obs.wrist_px.reset();
    // First frame: many iterations from the nominal pose; then a warm start, with more rounds
    // while the caps are not yet reached (a fast motion between two frames).
    // Within the active ranges first (the previous frame's posture clamped back into them, so a
    // finger leaves its passive range when the force lets go); only caps still out of reach push
    // the fingers on into their passive ranges, from there.
    const int rounds = first_ ? 8 : 1;
    for (int r = 0; r < rounds + p_.extra_rounds; ++r) {
      solver_.fit(truth_[h], obs, registration::ImageEvidence{}, &nominal, &q_[h]);
      if (r + 1 >= rounds && mean_cap_distance(truth_[h], q_[h], obs) <= p_.target_residual_m) break;
    }
    for (int r = 0; r < p_.extra_rounds && mean_cap_distance(truth_[h], q_[h], obs) > p_.target_residual_m; ++r)
      solver_.fit(pushed_[h], obs, registration::ImageEvidence{}, &nominal, &q_[h]);
    q_[h].little_independent = true;
    const auto& lim = truth_[h].limits;
    Vec3 little = q_[h].ring() + p_.little_offset + Vec3(p_.little_sway * std::sin(2 * units::kPi * 0.7 * t), 0, 0);
    for (int i = 0; i < 3; ++i)
      little[i] = std::clamp(little[i], lim.lower[hand::kLittleMcpFlexion + i], lim.upper[hand::kLittleMcpFlexion + i]);
    q_[h].set_little(little);
    residual_[h] = mean_cap_distance(truth_[h], q_[h], obs);
  }
  first_ = false;
}

}  // namespace spidar::sim
