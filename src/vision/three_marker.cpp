#include "spidar/vision/three_marker.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace spidar::vision {
namespace {

/// The paper's triad (eqs 15–20) as a rotation: columns x', y', z'. `frame` names the frame in
/// errors.
Result<Mat3> triad(const Vec3& v1, const Vec3& v2, const Vec3& v3, const char* frame) {
  const Vec3 x = v2 - v1;
  const Vec3 a = v3 - v1;
  const double longest = std::max({x.norm(), a.norm(), (v3 - v2).norm()});
  if (x.norm() < 0.01 || a.norm() < 0.01 || (v3 - v2).norm() < 0.01) {
    return Error{std::string("markers in ") + frame +
                 " coordinates: expected markers at least 0.01 m apart"};
  }
  const Vec3 y = a - (x.dot(a) / x.dot(x)) * x;
  if (y.norm() < 0.01 * longest) {
    return Error{std::string("markers in ") + frame +
                 " coordinates: expected three non-collinear markers (m3 lies within 1 % of the "
                 "line m1-m2)"};
  }
  const Vec3 z = x.cross(y);
  Mat3 R;
  R.col(0) = x.normalized();
  R.col(1) = y.normalized();
  R.col(2) = z.normalized();
  return R;
}

}  // namespace

Result<ThreeMarkerResult> three_marker_extrinsics(const std::array<MarkerPair, 3>& m) {
  for (int i = 0; i < 3; ++i) {
    if (!m[i].p_W.allFinite() || !m[i].p_C.allFinite()) {
      return Error{"marker m" + std::to_string(i + 1) + ": expected finite coordinates"};
    }
  }
  auto R_WF = triad(m[0].p_W, m[1].p_W, m[2].p_W, "world");
  if (!R_WF) return R_WF.error();
  auto R_CF = triad(m[0].p_C, m[1].p_C, m[2].p_C, "camera");
  if (!R_CF) return R_CF.error();
  const Mat3 R_CW = *R_CF * R_WF->transpose();
  ThreeMarkerResult out;
  out.X_CW = {Quat(R_CW).normalized(), m[0].p_C - R_CW * m[0].p_W};
  double sum = 0;
  for (const auto& k : m) {
    const double e = (out.X_CW * k.p_W - k.p_C).norm();
    sum += e * e;
    out.max_m = std::max(out.max_m, e);
  }
  out.rms_m = std::sqrt(sum / 3.0);
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double dW = (m[i].p_W - m[j].p_W).norm();
    const double dC = (m[i].p_C - m[j].p_C).norm();
    out.scale_mismatch = std::max(out.scale_mismatch, std::abs(dC - dW) / dW);
  }
  return out;
}

}  // namespace spidar::vision
