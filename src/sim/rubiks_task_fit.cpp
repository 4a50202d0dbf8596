// RubiksTask::fit_to_hands: the script's fingertip paths made reachable by the user's own hands.
#include <algorithm>
#include <cmath>
#include <exception>
#include <thread>

#include "spidar/hand/kinematics.hpp"
#include "spidar/core/thread_name.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/sim/finger_hold.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/user_hands.hpp"

namespace spidar::sim {
namespace {

/// The hand with its finger joints' ranges narrowed by `margin` [rad] at both ends (a range
/// narrower than twice the margin shrinks to its middle); the wrist stays free.
hand::HandModel with_inset_limits(const hand::HandModel& model, double margin) {
  hand::HandModel m = model;
  for (int p = hand::kThumbCmcFlexion; p < hand::kParamCount; ++p) {
    double& lo = m.limits.lower[p];
    double& hi = m.limits.upper[p];
    if (!std::isfinite(lo) || !std::isfinite(hi)) continue;
    const double d = std::min(margin, 0.5 * (hi - lo));
    lo += d;
    hi -= d;
  }
  return m;
}

/// A fitted touching position (grasp frame) kept on its hand's layers, `closed` (0 open … 1
/// closed) of the way: a fingertip on a side face keeps its proxy sphere (radius r) 1 mm clear of
/// the boundary between the top and the middle layer (z = pitch / 2), below it for the left
/// (holding) hand, above it for the right (turning) hand. Fingers spread by the limit margin would
/// otherwise press on the other hand's layer and hold it against the turn (lockstep physics, the
/// demo's user, margin 0.1 rad: the left index reached the top layer and the first turn stopped at
/// 62°). The script's own contacts keep 4.4 mm (left index) and 5.3 mm (right hand).
/// `n`: the outward normal of the contact's face (a contact on the top face is left as it is).
/// An object that is not a cube has no layers: its fitted positions are left as they are (moved
/// below a layer boundary it does not have, a left fingertip on a can was pressed where the
/// user's finger could not follow: the demo's caps missed by 1.37 mm, 0.26 mm without the move).
Vec3 keep_grip(const Vec3& fitted, const Vec3& n, double closed, bool left, const RubiksTaskParams& tp) {
  constexpr double kGap = 0.001;  // [m]
  if (!tp.has_cube || std::abs(n.z()) > 0.5) return fitted;
  const double boundary = 0.5 * tp.pitch;
  const double z = left ? std::min(fitted.z(), boundary - tp.proxy_radius - kGap)
                        : std::max(fitted.z(), boundary + tp.proxy_radius + kGap);
  Vec3 p = fitted;
  p.z() += closed * (z - p.z());
  return p;
}

/// A fitted touching position (grasp frame, cube centre at the origin) moved along the contact's
/// outward normal n onto the plane where the fingertip's proxy sphere (radius r) touches the face,
/// `closed` (0 open … 1 closed) of the way. The fit may leave a fingertip off its face where the
/// hand cannot reach the script's contact point (fingers at their limits); along the face it may
/// go wherever the hand can take it, but off it the finger would not touch: its squeeze would
/// press on nothing, or the cap would be pressed where the finger cannot follow.
Vec3 onto_face(const Vec3& fitted, const Vec3& n, double closed, const RubiksTaskParams& tp) {
  const double off = fitted.dot(n) - (tp.half + tp.proxy_radius);
  return fitted - closed * off * n;
}

}  // namespace

void RubiksTask::fit_to_hands(const std::array<hand::HandModel, 2>& hands, double dt_s,
                              const std::array<double, 2>& limit_margin_rad) {
  fit_dt_ = std::clamp(dt_s, 1e-3, 0.1);
  // A little past the end, so that the last interval interpolates between fitted samples.
  const auto n = static_cast<std::size_t>(std::ceil((p_.duration + 0.5) / fit_dt_)) + 2;
  // Each hand on its own thread (the right one on a second thread): the hands share nothing but
  // the script, which is read-only here, and each writes only its own entries. Same results as
  // one after the other, in half the time on two cores (Scene::load's longest step).
  auto fit_hand = [&](int h) {
    registration::SuccessiveAdjustment solver(fingertip_ik_params(UserHandsParams{}));
    const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
    std::vector<std::array<Vec3, 4>> table(n);
    fit_shift_max_[h] = 0.0;
    // Fitted inside the joint ranges by the margin: the device's caps lie past the touching
    // positions (pressed into the faces, pulled by the strings) and the user's fingers must be
    // able to follow them there, not already be at a limit.
    const double margin = std::isfinite(limit_margin_rad[h]) ? std::max(0.0, limit_margin_rad[h]) : 0.0;
    const hand::HandModel model = with_inset_limits(hands[h], margin);
    // Shaped fingers: two more passes toward the faces (and the hand's own layers).
    const int passes = p_.shaped_fingers ? 3 : (margin > 0 ? 2 : 1);
    hand::HandParams q = script_nominal_local(0.0, side);
    std::vector<hand::HandParams> poses(n);
    std::vector<std::array<device::FingertipHold, 4>> holds(p_.shaped_fingers ? n : 0);
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
      // Then again toward the nearest positions on the faces (onto_face) and, with a margin, that
      // keep the grip (keep_grip), so that the hand takes them (moving its other fingers and wrist
      // for it). The last pass keeps what the hand reaches.
      registration::HandObservation target = obs;
      for (int pass = 0; pass < passes; ++pass) {
        for (int r = 0; r < (k == 0 ? 8 : 2); ++r)
          solver.fit(model, target, registration::ImageEvidence{}, &prior, &q);
        const hand::HandPoints pts = hand::forward_kinematics(model, q);
        const bool last = pass + 1 == passes;
        for (int f = 0; f < hand::kFingertipCount; ++f) {
          const Vec3 normal = contact_normal(4 * h + f);
          Vec3 p = pts.p_W_fingertip[f];
          if (p_.shaped_fingers && !last) p = onto_face(p, normal, closeness(t, side), p_);
          if (p_.shaped_fingers || margin > 0) p = keep_grip(p, normal, closeness(t, side), h == 0, p_);
          target.p_W_fingertip[f] = p;
        }
      }
      poses[k] = q;
      if (p_.shaped_fingers) holds[k] = finger_holds(hands[h], q);  // the user's own joint ranges
      for (int f = 0; f < hand::kFingertipCount; ++f) {
        table[k][f] = target.p_W_fingertip[f];
        fit_shift_max_[h] = std::max(fit_shift_max_[h], (table[k][f] - obs.p_W_fingertip[f]).norm());
      }
    }
    fitted_[h] = std::move(table);
    fitted_q_[h] = std::move(poses);
    fitted_hold_[h] = std::move(holds);
  };
  std::exception_ptr right_failed;
  std::thread right([&] {
    core::set_thread_name("spidar-fit");
    try {
      fit_hand(1);
    } catch (...) {
      right_failed = std::current_exception();
    }
  });
  try {
    fit_hand(0);
  } catch (...) {
    right.join();
    throw;
  }
  right.join();
  if (right_failed) std::rethrow_exception(right_failed);
}

}  // namespace spidar::sim
