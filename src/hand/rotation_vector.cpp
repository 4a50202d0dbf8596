#include "spidar/hand/rotation_vector.hpp"

#include <cmath>

namespace spidar::hand {
namespace {
// Below this angle the Taylor series (to θ⁴) are used: their truncation error is below θ⁶/5040
// ≈ 2e-16, and the closed forms would lose digits to cancellation.
constexpr double kSmallAngle = 1e-2;
}  // namespace

Mat3 skew(const Vec3& v) {
  Mat3 S;
  S << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return S;
}

Mat3 rotation_from_vector(const Vec3& r) {
  const double t2 = r.squaredNorm();
  const double t = std::sqrt(t2);
  double a;  // sin θ / θ
  double b;  // (1 − cos θ) / θ²
  if (t < kSmallAngle) {
    a = 1.0 - t2 / 6.0 + t2 * t2 / 120.0;
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
  } else {
    a = std::sin(t) / t;
    b = (1.0 - std::cos(t)) / t2;
  }
  const Mat3 K = skew(r);
  return Mat3::Identity() + a * K + b * K * K;
}

Mat3 so3_left_jacobian(const Vec3& r) {
  const double t2 = r.squaredNorm();
  const double t = std::sqrt(t2);
  double b;  // (1 − cos θ) / θ²
  double c;  // (θ − sin θ) / θ³
  if (t < kSmallAngle) {
    b = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    c = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    b = (1.0 - std::cos(t)) / t2;
    c = (t - std::sin(t)) / (t2 * t);
  }
  const Mat3 K = skew(r);
  return Mat3::Identity() + b * K + c * K * K;
}

}  // namespace spidar::hand
