#pragma once
/// A human fingertip held toward its goal: the simulated device's model of the user's finger.
///
/// The fingertip (its cap) is a point mass tied to where the user wants it (the goal) by a
/// spring and a damper; the strings and contacts push it away from the goal as a real finger
/// yields. A real fingertip is not equally compliant in every direction: it yields easily where
/// its joints can move it (flexion, for a pinch) and hardly at all where they cannot (along a
/// straight finger, sideways for a finger with no abduction, past a joint at its limit) — its
/// stiffness ellipsoid. A FingertipHold gives that shape; the impedance gives the scale.
#include "spidar/core/types.hpp"

namespace spidar::device {

/// The isotropic fingertip: the stiffness along the finger's most compliant direction.
struct FingertipImpedance {
  double mass = 0.015;      ///< [kg] effective fingertip mass
  double stiffness = 300;   ///< [N/m] finger held toward its goal
  double damping = 4.0;     ///< [N·s/m]
  /// How far from the goal a FingertipHold's stiffer directions hold [m]: past it only the
  /// isotropic spring grows, as the hand and arm give way (a finger is stiff for small
  /// deflections; a fingertip held centimetres from its goal by a contact must not snap back at
  /// metres per second when it lets go). 1.5 mm at 64 × 300 N/m: up to 29 N beside it, more than
  /// the device displays.
  double hold_range = 0.0015;
};

/// The shape of a fingertip's stiffness: principal axes (columns of R_WE, world frame,
/// orthonormal) and, along each, how many times stiffer than the impedance's `stiffness` the
/// fingertip is (≥ 1; 1 everywhere is the isotropic fingertip). Damping scales with the square
/// root, so every axis keeps the impedance's damping ratio. Beyond the impedance's hold_range
/// the stiffness past the isotropic one no longer grows.
struct FingertipHold {
  Mat3 R_WE = Mat3::Identity();
  Vec3 scale = Vec3::Ones();
};

/// Largest stiffness scale the device's integration accepts: with the default impedance and
/// sub-steps of 0.25 ms, ω·dt = 0.29 at 64 × 300 N/m (semi-implicit Euler is stable below 2).
inline constexpr double kMaxHoldScale = 64.0;

/// The hold clamped to what the integration accepts: scales in [1, kMaxHoldScale]; a hold with a
/// non-finite entry becomes the isotropic one.
FingertipHold sanitized(const FingertipHold& hold);

/// One semi-implicit Euler step of a fingertip (position p_W, velocity v_W, world [m, m/s])
/// toward its goal p_W_goal under the external force f_W [N] (strings, contacts) for dt [s].
void step_fingertip(const FingertipImpedance& imp, const FingertipHold& hold, const Vec3& p_W_goal,
                    const Vec3& f_W, double dt, Vec3& p_W, Vec3& v_W);

}  // namespace spidar::device
