#pragma once
/// The stiffness ellipsoid of a user's fingertips, from their hand: the simulated device's
/// FingertipHold (device/fingertip_impedance.hpp) for a hand model at a pose.
///
/// A fingertip yields to a force f through its digit's joints: Δp = J·C·Jᵀ·f, with J the
/// fingertip's Jacobian in the digit's own parameters (the wrist stays put) and C the joints'
/// compliance. C is equal for every joint away from its limits and falls to `limit_floor` of it
/// at a limit (within `limit_zone_rad` of it): a finger at its abduction limit hardly yields
/// sideways. The hold's axes are the eigenvectors of J·C·Jᵀ; each axis's stiffness scale is the
/// most compliant direction's compliance of the same digit free of its limits over this axis's
/// compliance (≥ 1, so the impedance's stiffness is the finger's softest), clamped to
/// kMaxHoldScale. Directions the digit cannot move in at all (along a straight finger; sideways
/// for the middle finger, which has no abduction) get the largest scale.
#include <array>

#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::sim {

struct FingerHoldParams {
  double limit_zone_rad = 0.15;  ///< a joint stiffens within this distance of a limit [rad]
  double limit_floor = 0.01;     ///< its compliance at the limit, relative to a free joint
};

/// The holds of the four measured fingertips (thumb, index, middle, ring) of `model` at `q`, in
/// the frame q's wrist pose is given in.
std::array<device::FingertipHold, hand::kFingertipCount> finger_holds(const hand::HandModel& model,
                                                                      const hand::HandParams& q,
                                                                      const FingerHoldParams& p = {});

}  // namespace spidar::sim
