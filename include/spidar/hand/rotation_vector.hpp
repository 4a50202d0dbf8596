#pragma once
/// The wrist's rotation-vector parameterisation and its exact derivative.
///
/// R(r) = exp([r]×). For a point fixed in the hand, p_W = p_W_wrist + R(r)·p_H, the derivative
/// with respect to r is exact (no local parameterisation):
///   ∂p_W/∂r = −[R(r)·p_H]× · J_l(r),
///   J_l(r) = I + (1 − cos θ)/θ² [r]× + (θ − sin θ)/θ³ [r]×²,  θ = ‖r‖,
/// the left Jacobian of SO(3): exp(r + δ) ≈ exp([J_l(r)·δ]×)·exp(r). Both are evaluated with
/// Taylor series for small θ, so they are smooth through r = 0.
#include "spidar/core/types.hpp"

namespace spidar::hand {

/// [v]×, the matrix with [v]×·w = v × w.
Mat3 skew(const Vec3& v);

/// R = exp([r]×) for a rotation vector r [rad].
Mat3 rotation_from_vector(const Vec3& r);

/// The left Jacobian J_l(r) of SO(3) (see the file comment).
Mat3 so3_left_jacobian(const Vec3& r);

}  // namespace spidar::hand
