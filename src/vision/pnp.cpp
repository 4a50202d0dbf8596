#include "spidar/vision/pnp.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <string>

#include "opencv_interop.hpp"

namespace spidar::vision {

std::vector<double> reprojection_errors(const Camera& camera, const std::vector<Vec3>& p_W,
                                        const std::vector<Vec2>& uv) {
  std::vector<double> e(std::min(p_W.size(), uv.size()));
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = (camera.project(p_W[i]) - uv[i]).norm();
  return e;
}

Result<PnpResult> solve_pnp(const Intrinsics& intrinsics, const std::vector<Vec3>& p_W,
                            const std::vector<Vec2>& uv) {
  if (auto s = validate_intrinsics(intrinsics); !s.ok()) return Error{"intrinsics: " + s.error().message};
  if (p_W.size() != uv.size()) {
    return Error{"pnp: expected one pixel per marker, got " + std::to_string(p_W.size()) +
                 " markers and " + std::to_string(uv.size()) + " pixels"};
  }
  if (p_W.size() < 4) {
    return Error{"pnp: expected at least 4 markers, got " + std::to_string(p_W.size())};
  }
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    if (!p_W[i].allFinite() || !uv[i].allFinite()) {
      return Error{"pnp: marker " + std::to_string(i) + ": expected finite coordinates"};
    }
  }
  // Degeneracy: all markers on one line (in the world).
  Vec3 mean = Vec3::Zero();
  for (const auto& p : p_W) mean += p;
  mean /= static_cast<double>(p_W.size());
  Mat3 S = Mat3::Zero();
  for (const auto& p : p_W) S += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
  const double spread = std::sqrt(std::max(eig.eigenvalues()(2), 0.0));
  if (spread < 1e-3 || std::sqrt(std::max(eig.eigenvalues()(1), 0.0)) < 1e-3 * spread) {
    return Error{"pnp: expected markers spread over a plane or volume; they lie (nearly) on one "
                 "line or point"};
  }

  std::vector<cv::Point3d> obj(p_W.size());
  std::vector<cv::Point2d> img(uv.size());
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    obj[i] = {p_W[i].x(), p_W[i].y(), p_W[i].z()};
    img[i] = {uv[i].x(), uv[i].y()};
  }
  const cv::Mat K = detail::to_cv(intrinsics.K());
  const cv::Mat dist = detail::distortion_to_cv(intrinsics.distortion);
  cv::Mat rvec, tvec;
  bool ok = false;
  try {
    ok = cv::solvePnP(obj, img, K, dist, rvec, tvec, false, cv::SOLVEPNP_SQPNP);
    if (ok) cv::solvePnPRefineLM(obj, img, K, dist, rvec, tvec);
  } catch (const cv::Exception& e) {
    return Error{std::string("pnp: OpenCV failed: ") + e.what()};
  }
  if (!ok) return Error{"pnp: no solution for these markers"};
  PnpResult out;
  out.X_CW = detail::pose_from_rvec_tvec(rvec, tvec);
  if (!out.X_CW.p.allFinite() || !out.X_CW.R.coeffs().allFinite()) {
    return Error{"pnp: the solution is not finite"};
  }
  const Camera cam(intrinsics, out.X_CW);
  for (std::size_t i = 0; i < p_W.size(); ++i) {
    if (cam.depth(p_W[i]) <= 0) {
      return Error{"pnp: marker " + std::to_string(i) +
                   " lies behind the solved camera; check the marker/pixel pairing"};
    }
  }
  out.residuals_px = reprojection_errors(cam, p_W, uv);
  double sum = 0;
  for (double e : out.residuals_px) {
    sum += e * e;
    out.max_px = std::max(out.max_px, e);
  }
  out.rms_px = std::sqrt(sum / static_cast<double>(out.residuals_px.size()));
  return out;
}

}  // namespace spidar::vision
