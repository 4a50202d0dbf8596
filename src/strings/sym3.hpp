#pragma once
// Internal: small dense solves used on the servo path (no pivoting, no allocation).
#include <cmath>

#include "spidar/core/types.hpp"

namespace spidar::strings::detail {

/// Solves the symmetric 3×3 system A x = b by cofactors. Returns false (x untouched) when
/// |det A| ≤ rel_tol · ‖A‖³ (max-norm), i.e. when A is numerically singular.
inline bool solve_sym3(const Mat3& A, const Vec3& b, Vec3& x, double rel_tol = 1e-12) {
  const double c00 = A(1, 1) * A(2, 2) - A(1, 2) * A(1, 2);
  const double c01 = A(0, 2) * A(1, 2) - A(0, 1) * A(2, 2);
  const double c02 = A(0, 1) * A(1, 2) - A(0, 2) * A(1, 1);
  const double c11 = A(0, 0) * A(2, 2) - A(0, 2) * A(0, 2);
  const double c12 = A(0, 1) * A(0, 2) - A(0, 0) * A(1, 2);
  const double c22 = A(0, 0) * A(1, 1) - A(0, 1) * A(0, 1);
  const double det = A(0, 0) * c00 + A(0, 1) * c01 + A(0, 2) * c02;
  const double scale = A.cwiseAbs().maxCoeff();
  if (!(std::abs(det) > rel_tol * scale * scale * scale)) return false;
  const double inv = 1.0 / det;
  x = inv * Vec3(c00 * b[0] + c01 * b[1] + c02 * b[2], c01 * b[0] + c11 * b[1] + c12 * b[2],
                 c02 * b[0] + c12 * b[1] + c22 * b[2]);
  return true;
}

}  // namespace spidar::strings::detail
