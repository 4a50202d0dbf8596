#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/lens_undistortion.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "spidar/core/atomic_write.hpp"
#include "spidar/core/units.hpp"

namespace spidar::vision {
namespace {

double positive_focal(const core::ConfigNode& node) {
  return core::require_in_range(node, node.as_double(), 1.0, 1e6, "px");
}

Pose parse_pose(const core::ConfigNode& node) {
  node.expect_keys({"position", "rotation_vector", "look_at"});
  const Vec3 p_WC = node["position"].as_vec3();
  const bool has_rv = node.has("rotation_vector");
  const bool has_look = node.has("look_at");
  if (has_rv == has_look) node.fail("expected exactly one of rotation_vector or look_at");
  if (has_look) {
    const auto target = node["look_at"];
    const Vec3 p_W_target = target.as_vec3();
    if ((p_W_target - p_WC).norm() < 1e-6) target.fail("expected a point away from the camera");
    return look_at(p_WC, p_W_target);
  }
  const auto rv = node["rotation_vector"];
  const Vec3 r = rv.as_vec3();
  if (r.norm() > 4.0 * units::kPi) rv.fail("expected a rotation vector in radians (norm <= 4π)");
  return Pose::FromRotationVector(r, p_WC).inverse();
}

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(17) << v;
  return os.str();
}

std::string vec(std::initializer_list<double> v) {
  std::string s = "[";
  bool first = true;
  for (double x : v) {
    s += (first ? "" : ", ") + num(x);
    first = false;
  }
  return s + "]";
}

}  // namespace

CameraFile parse_camera_file(const core::ConfigNode& root) {
  root.expect_keys({"camera"});
  const auto node = root["camera"];
  node.expect_keys(
      {"image_size", "fx", "fy", "cx", "cy", "distortion", "pose", "calibration"});
  Intrinsics in;
  const auto size = node["image_size"];
  const auto wh = size.as_doubles();
  if (wh.size() != 2) size.fail("expected [width, height] in px");
  for (double v : wh) {
    if (v != std::floor(v) || v < 16 || v > 16384) {
      size.fail("expected whole numbers of pixels in [16, 16384]");
    }
  }
  in.width = static_cast<int>(wh[0]);
  in.height = static_cast<int>(wh[1]);
  in.fx = positive_focal(node["fx"]);
  in.fy = positive_focal(node["fy"]);
  const auto cx = node["cx"];
  in.cx = core::require_in_range(cx, cx.as_double(), -0.5, in.width - 0.5, "px");
  const auto cy = node["cy"];
  in.cy = core::require_in_range(cy, cy.as_double(), -0.5, in.height - 0.5, "px");
  if (auto d = node.find("distortion")) {
    const auto k = d->as_doubles();
    if (k.size() != 5) {
      d->fail("expected 5 coefficients [k1, k2, p1, p2, k3], got " + std::to_string(k.size()));
    }
    in.distortion = {k[0], k[1], k[2], k[3], k[4]};
  }
  if (auto s = validate_intrinsics(in); !s.ok()) node.fail(s.error().message);
  // A lens whose distortion folds the image cannot be undistorted (LensUndistortion): refused
  // here, at its key, for every command that reads a camera file.
  if (auto d = node.find("distortion"); d && !in.distortion.is_zero())
    if (auto st = LensUndistortion::check(in); !st) d->fail(st.error().message);

  CameraFile out;
  out.source = root.file();
  out.camera = Camera(in, parse_pose(node["pose"]));
  if (auto c = node.find("calibration")) {
    c->expect_keys({"intrinsics_rms_px", "extrinsics_rms_px", "extrinsics_rms_m", "method"});
    if (auto v = c->find("intrinsics_rms_px")) out.calibration.intrinsics_rms_px = v->as_double();
    if (auto v = c->find("extrinsics_rms_px")) out.calibration.extrinsics_rms_px = v->as_double();
    if (auto v = c->find("extrinsics_rms_m")) out.calibration.extrinsics_rms_m = v->as_double();
    if (auto v = c->find("method")) out.calibration.method = v->as_string();
  }
  return out;
}

CameraFile load_camera_file(const std::string& path) {
  return parse_camera_file(core::ConfigNode::LoadFile(path));
}

std::string camera_file_yaml(const Camera& camera, const CalibrationNotes& notes) {
  const auto& in = camera.intrinsics();
  const auto& d = in.distortion;
  const Pose X_WC = camera.X_WC();
  const Eigen::AngleAxisd aa(X_WC.R);
  const Vec3 rv = aa.angle() * aa.axis();
  std::ostringstream os;
  os << "# spidar-mr camera (vision::Camera). OpenCV pinhole convention: camera x right, y down,\n"
     << "# z forward; pixel (0, 0) is the centre of the top-left pixel. World frame: origin at the\n"
     << "# SPIDAR-8 frame centre, z up, x to the user's right, y away from the user. SI units.\n"
     << "camera:\n"
     << "  image_size: [" << in.width << ", " << in.height << "]  # width, height [px]\n"
     << "  fx: " << num(in.fx) << "  # [px]\n"
     << "  fy: " << num(in.fy) << "  # [px]\n"
     << "  cx: " << num(in.cx) << "  # [px]\n"
     << "  cy: " << num(in.cy) << "  # [px]\n"
     << "  distortion: " << vec({d.k1, d.k2, d.p1, d.p2, d.k3}) << "  # k1, k2, p1, p2, k3\n"
     << "  pose:  # the camera in the world, X_WC\n"
     << "    position: " << vec({X_WC.p.x(), X_WC.p.y(), X_WC.p.z()})
     << "  # camera centre [m]\n"
     << "    rotation_vector: " << vec({rv.x(), rv.y(), rv.z()})
     << "  # R_WC [rad]; columns = camera x, y, z in world\n";
  if (notes.intrinsics_rms_px || notes.extrinsics_rms_px || notes.extrinsics_rms_m ||
      !notes.method.empty()) {
    os << "  calibration:\n";
    if (!notes.method.empty()) os << "    method: \"" << notes.method << "\"\n";
    if (notes.intrinsics_rms_px)
      os << "    intrinsics_rms_px: " << num(*notes.intrinsics_rms_px) << "\n";
    if (notes.extrinsics_rms_px)
      os << "    extrinsics_rms_px: " << num(*notes.extrinsics_rms_px) << "\n";
    if (notes.extrinsics_rms_m)
      os << "    extrinsics_rms_m: " << num(*notes.extrinsics_rms_m) << "\n";
  }
  return os.str();
}

Status save_camera_file(const std::string& path, const Camera& camera,
                        const CalibrationNotes& notes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  // Whole or not at all (temporary file, then rename), through a symbolic link to its target.
  try {
    core::write_file_atomic(path, camera_file_yaml(camera, notes));
  } catch (const core::FileError& e) {
    return Error{std::string(e.what()) + " (writing the camera file)"};
  }
  return Ok{};
}

}  // namespace spidar::vision
