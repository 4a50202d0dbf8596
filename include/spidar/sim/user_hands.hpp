#pragma once
/// The simulated user's real hands: the ground truth the synthetic camera films.
///
/// Each hand has the user's own proportions (not the registration model's) and an independent
/// little finger. Its posture at time t is the one that puts the four fingertip caps exactly where
/// the simulated SPIDAR-8 has them (they yield to the displayed forces, so they are not the
/// script's goals), closest to the script's nominal pose: a small inverse-kinematics fit (the
/// registration solver with the 3D fingertip term and a prior toward the nominal pose, no image),
/// warm-started from the previous frame. The residual (how far the fitted caps are from the
/// device's) is kept as a check: a few tenths of a millimetre when the posture is reachable.
#include <array>
#include <span>

#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/joint_limits.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::sim {

struct UserHandsParams {
  double fingertip_sigma_m = 0.0002;   ///< how tightly the caps are matched [m]
  double wrist_sigma_m = 0.10;         ///< freedom of the wrist around the nominal pose [m]
  double rotation_sigma_rad = 1.0;     ///< ... of the hand's rotation [rad]
  double joint_sigma_rad = 1.5;        ///< ... of the finger joints [rad]
  int iterations = 40;                 ///< per round of an update (warm start)
  /// Rounds an update may add while the caps' mean residual exceeds target_residual_m.
  int extra_rounds = 4;
  double target_residual_m = 0.0002;
  /// How far past their active ranges the caps may push the fingers' MCP joints.
  hand::PassiveRange passive{};
  /// The little finger's own posture relative to the ring finger's (MCP flexion, abduction, DIP)
  /// [rad]; it also sways with this amplitude [rad] at 0.7 Hz, as a real little finger does.
  Vec3 little_offset{0.15, 0.06, 0.12};
  double little_sway = 0.12;
};

/// The registration solver's settings for fitting a hand to fingertip positions alone (no image),
/// tight on the caps, loose around the prior: the user's inverse kinematics.
registration::RegistrationParams fingertip_ik_params(const UserHandsParams& params);

/// The simulated user's elbows (left, right) [m, world]: where the forearms point at the start of
/// the script (the nominal poses at t = 0, forearms in line with the hands), forearm_length_m from
/// the wrists. The user's arms stay there while the hands turn (SyntheticCameraParams::elbows_W).
std::array<Vec3, 2> user_elbows(const RubiksTask& task, double forearm_length_m = 0.26);

class UserHands {
 public:
  /// `truth`: the user's hands (left, right) with their own proportions.
  UserHands(const std::array<hand::HandModel, 2>& truth, const RubiksTask& task,
            const UserHandsParams& params = {});
  /// Poses both hands for time t [s] (script time) with the eight caps at p_W_caps (left thumb …
  /// ring, right thumb … ring) [m].
  void update(double t_s, std::span<const Vec3> p_W_caps);
  const std::array<hand::HandParams, 2>& params() const { return q_; }
  const std::array<hand::HandModel, 2>& models() const { return truth_; }
  /// The box the postures stay in: the hands' joint ranges widened by the passive range.
  const hand::ParamLimits& reach_limits(int hand) const { return pushed_[hand].limits; }
  /// Mean distance of the fitted caps from the device's at the last update [m], per hand.
  const std::array<double, 2>& cap_residual_m() const { return residual_; }

 private:
  std::array<hand::HandModel, 2> truth_;
  std::array<hand::HandModel, 2> pushed_;  ///< truth_ with the passive ranges
  const RubiksTask& task_;
  UserHandsParams p_;
  registration::SuccessiveAdjustment solver_;
  std::array<hand::HandParams, 2> q_;
  std::array<double, 2> residual_{0.0, 0.0};
  bool first_ = true;
};

}  // namespace spidar::sim
