#include "spidar/sim/finger_hold.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "spidar/hand/kinematics.hpp"

namespace spidar::sim {
namespace {

/// Relative compliance of parameter `param` at value v: 1 away from the limits, falling linearly
/// to `floor` at a limit.
double joint_compliance(const hand::HandModel& model, int param, double v, const FingerHoldParams& p) {
  const double lo = model.limits.lower[param], hi = model.limits.upper[param];
  double d = std::numeric_limits<double>::infinity();
  if (std::isfinite(lo)) d = std::min(d, v - lo);
  if (std::isfinite(hi)) d = std::min(d, hi - v);
  if (!(p.limit_zone_rad > 0)) return 1.0;
  return std::clamp(d / p.limit_zone_rad, p.limit_floor, 1.0);
}

}  // namespace

std::array<device::FingertipHold, hand::kFingertipCount> finger_holds(const hand::HandModel& model,
                                                                      const hand::HandParams& q,
                                                                      const FingerHoldParams& p) {
  constexpr double kStep = 1e-6;  // [rad], central differences
  std::array<device::FingertipHold, hand::kFingertipCount> holds;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    const hand::DigitParams d = hand::digit_params(f);
    Mat3 C_free = Mat3::Zero(), C = Mat3::Zero();  // J·C·Jᵀ [m²/rad² per unit compliance]
    for (int param : {d.flexion, d.abduction, d.distal}) {
      if (param < 0) continue;
      hand::HandParams plus = q, minus = q;
      plus[param] += kStep;
      minus[param] -= kStep;
      const Vec3 j = (hand::forward_kinematics(model, plus).p_W_fingertip[f] -
                      hand::forward_kinematics(model, minus).p_W_fingertip[f]) /
                     (2 * kStep);
      C_free += j * j.transpose();
      C += joint_compliance(model, param, q[param], p) * j * j.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Mat3> free(C_free, Eigen::EigenvaluesOnly);
    const double softest = free.eigenvalues().maxCoeff();
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(C);
    device::FingertipHold& h = holds[static_cast<std::size_t>(f)];
    h.R_WE = eig.eigenvectors();
    for (int i = 0; i < 3; ++i) {
      const double c = eig.eigenvalues()[i];
      h.scale[i] = c * device::kMaxHoldScale > softest ? softest / c : device::kMaxHoldScale;
    }
    h = device::sanitized(h);
  }
  return holds;
}

}  // namespace spidar::sim
