// RubiksTask::fit_to_hands: the script's fingertip paths made reachable by the user's own hands.
#include <algorithm>
#include <cmath>

#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/user_hands.hpp"

namespace spidar::sim {

void RubiksTask::fit_to_hands(const std::array<hand::HandModel, 2>& hands, double dt_s) {
  fit_dt_ = std::clamp(dt_s, 1e-3, 0.1);
  // A little past the end, so that the last interval interpolates between fitted samples.
  const auto n = static_cast<std::size_t>(std::ceil((p_.duration + 0.5) / fit_dt_)) + 2;
  registration::SuccessiveAdjustment solver(fingertip_ik_params(UserHandsParams{}));
  for (int h = 0; h < 2; ++h) {
    const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
    std::vector<std::array<Vec3, 4>> table(n);
    fit_shift_max_[h] = 0.0;
    hand::HandParams q = script_nominal_local(0.0, side);
    std::vector<hand::HandParams> poses(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) * fit_dt_;
      registration::HandObservation obs;
      for (int f = 0; f < hand::kFingertipCount; ++f) {
        // Where the finger touches: it stops at the face, the squeeze is only its setpoint.
        obs.p_W_fingertip[f] = script_path(t, 4 * h + f) - squeeze_path(t, 4 * h + f);
        obs.fingertip_valid[f] = true;
      }
      const hand::HandParams prior = script_nominal_local(t, side);
      // Warm start along the script; the first sample from the nominal pose, with more rounds.
      for (int r = 0; r < (k == 0 ? 8 : 2); ++r)
        solver.fit(hands[h], obs, registration::ImageEvidence{}, &prior, &q);
      poses[k] = q;
      const hand::HandPoints pts = hand::forward_kinematics(hands[h], q);
      for (int f = 0; f < hand::kFingertipCount; ++f) {
        table[k][f] = pts.p_W_fingertip[f];
        fit_shift_max_[h] = std::max(fit_shift_max_[h], (table[k][f] - obs.p_W_fingertip[f]).norm());
      }
    }
    fitted_[h] = std::move(table);
    fitted_q_[h] = std::move(poses);
  }
}

}  // namespace spidar::sim
