// vision::Camera: projection against OpenCV, its Jacobian against finite differences, unproject
// round trips, the default rig camera and camera.yaml.
#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <random>

#include "spidar/core/units.hpp"
#include "temp_path.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/camera_config.hpp"

namespace spidar::vision {
namespace {

Camera distorted_camera() {
  Intrinsics in;
  in.fx = 560.0;
  in.fy = 548.0;
  in.cx = 322.3;
  in.cy = 236.9;
  in.distortion = {-0.21, 0.09, 0.0012, -0.0008, -0.02};
  return Camera(in, default_rig_camera().X_CW());
}

std::vector<Vec3> points_in_view(const Camera& cam, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(-0.15, 0.15), uy(-0.12, 0.12), uz(-0.1, 0.12);
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < n) {
    const Vec3 p(ux(rng), uy(rng), uz(rng));
    if (cam.in_image(cam.project(p))) out.push_back(p);
  }
  return out;
}

TEST(Camera, ProjectMatchesOpenCvProjectPoints) {
  for (const Camera& cam : {default_rig_camera(), distorted_camera()}) {
    const auto pts = points_in_view(cam, 50, 3);
    std::vector<cv::Point3d> obj;
    for (const auto& p : pts) obj.emplace_back(p.x(), p.y(), p.z());
    const Eigen::AngleAxisd aa(cam.X_CW().R);
    const Vec3 rv = aa.angle() * aa.axis();
    const cv::Mat rvec = (cv::Mat_<double>(3, 1) << rv.x(), rv.y(), rv.z());
    const cv::Mat tvec = (cv::Mat_<double>(3, 1) << cam.X_CW().p.x(), cam.X_CW().p.y(), cam.X_CW().p.z());
    const auto& in = cam.intrinsics();
    const cv::Mat K = (cv::Mat_<double>(3, 3) << in.fx, 0, in.cx, 0, in.fy, in.cy, 0, 0, 1);
    const auto& d = in.distortion;
    const cv::Mat dist = (cv::Mat_<double>(1, 5) << d.k1, d.k2, d.p1, d.p2, d.k3);
    std::vector<cv::Point2d> uv;
    cv::projectPoints(obj, rvec, tvec, K, dist, uv);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Vec2 ours = cam.project(pts[i]);
      EXPECT_NEAR(ours.x(), uv[i].x, 1e-9);
      EXPECT_NEAR(ours.y(), uv[i].y, 1e-9);
    }
  }
}

TEST(Camera, JacobianMatchesCentralDifferences) {
  for (const Camera& cam : {default_rig_camera(), distorted_camera()}) {
    for (const auto& p : points_in_view(cam, 40, 7)) {
      const ProjectionJacobian J = cam.projection_jacobian(p);
      ProjectionJacobian J_fd;
      const double h = 1e-6;
      for (int k = 0; k < 3; ++k) {
        Vec3 dp = Vec3::Zero();
        dp[k] = h;
        J_fd.col(k) = (cam.project(p + dp) - cam.project(p - dp)) / (2 * h);
      }
      EXPECT_LE((J - J_fd).norm(), 1e-6 * J.norm()) << "at " << p.transpose() << "\n" << J << "\n" << J_fd;
      ProjectionJacobian J2;
      EXPECT_TRUE(cam.project(p, &J2).isApprox(cam.project(p)));
      EXPECT_TRUE(J2.isApprox(J));
    }
  }
}

TEST(Camera, UnprojectInvertsProject) {
  const Camera cam = distorted_camera();
  for (const auto& p : points_in_view(cam, 50, 11)) {
    const Vec2 uv = cam.project(p);
    const Vec3 back = cam.unproject(uv, cam.depth(p));
    EXPECT_LT((back - p).norm(), 1e-9);
    const Vec3 ray = cam.ray_direction_W(uv);
    const Vec3 to_p = (p - cam.X_WC().p).normalized();
    EXPECT_NEAR(ray.dot(to_p), 1.0, 1e-12);
  }
  // Corners of the image also undistort consistently.
  for (const Vec2& uv : {Vec2(0, 0), Vec2(639, 0), Vec2(0, 479), Vec2(639, 479)}) {
    const Vec3 p_C = cam.unproject_camera(uv, 0.4);
    EXPECT_LT((cam.project_camera(p_C) - uv).norm(), 1e-9);
  }
}

TEST(Camera, BehindTheCameraIsFiniteNotNaN) {
  const Camera cam = default_rig_camera();
  const Vec3 behind = cam.X_WC() * Vec3(0.01, 0.02, -0.5);
  EXPECT_TRUE(cam.project(behind).allFinite());
  EXPECT_TRUE(cam.projection_jacobian(behind).allFinite());
  EXPECT_LT(cam.depth(behind), 0);
}

TEST(Camera, DefaultRigCameraLooksDownAtTheFrameCentre) {
  const Camera cam = default_rig_camera();
  EXPECT_LT((cam.project(Vec3::Zero()) - Vec2(319.5, 239.5)).norm(), 1e-9);
  const Vec3 c = cam.X_WC().p;
  EXPECT_NEAR(c.z(), 0.30, 1e-12);
  EXPECT_LT(c.y(), 0.0);  // on the user's side
  const Vec3 axis = cam.X_WC().R * Vec3::UnitZ();
  EXPECT_NEAR(units::rad_to_deg(std::asin(-axis.z())), 50.0, 1e-9);
  // x right in the world is right in the image; farther from the user is higher up.
  EXPECT_GT(cam.project(Vec3(0.05, 0, 0)).x(), 319.5);
  EXPECT_LT(cam.project(Vec3(0, 0.05, 0)).y(), 239.5);
  EXPECT_LT(cam.project(Vec3(0, 0, 0.05)).y(), 239.5);
}

TEST(CameraConfig, SaveLoadRoundTripsExactly) {
  const Camera cam = distorted_camera();
  CalibrationNotes notes;
  notes.intrinsics_rms_px = 0.123;
  notes.method = "chessboard + pnp";
  const std::string path = spidar::test::temp_dir("spidar_vision_camera") + "/camera.yaml";
  ASSERT_TRUE(save_camera_file(path, cam, notes).ok());
  const auto loaded = load_camera_file(path);
  EXPECT_EQ(loaded.calibration.method, notes.method);
  EXPECT_DOUBLE_EQ(*loaded.calibration.intrinsics_rms_px, 0.123);
  for (const auto& p : points_in_view(cam, 20, 5)) {
    EXPECT_LT((loaded.camera.project(p) - cam.project(p)).norm(), 1e-9);
  }
  std::filesystem::remove(path);
}

TEST(CameraConfig, ShippedFileIsTheDefaultRigCamera) {
  const auto f = load_camera_file(std::string(SPIDAR_SOURCE_DIR) + "/configs/camera.yaml");
  const Camera def = default_rig_camera();
  for (const auto& p : points_in_view(def, 20, 9)) {
    EXPECT_LT((f.camera.project(p) - def.project(p)).norm(), 1e-3);  // position printed to 0.1 mm
  }
}

TEST(CameraConfig, ErrorsNameFileLineAndKey) {
  const std::string base =
      "camera:\n  image_size: [640, 480]\n  fx: 500\n  fy: 500\n  cx: 319.5\n  cy: 239.5\n"
      "  pose:\n    position: [0, -0.25, 0.3]\n    look_at: [0, 0, 0]\n";
  EXPECT_NO_THROW(parse_camera_file(core::ConfigNode::Parse(base, "cam.yaml")));
  auto message = [](const std::string& text) {
    try {
      parse_camera_file(core::ConfigNode::Parse(text, "cam.yaml"));
    } catch (const core::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  auto replace = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_NE(message(replace("fx: 500", "fx: -3")).find("cam.yaml:3: camera.fx"), std::string::npos)
      << message(replace("fx: 500", "fx: -3"));
  EXPECT_NE(message(replace("cx: 319.5", "cx: 700")).find("camera.cx"), std::string::npos);
  EXPECT_NE(message(replace("    look_at: [0, 0, 0]\n", "")).find("exactly one of rotation_vector or look_at"),
            std::string::npos);
  EXPECT_NE(message(replace("image_size: [640, 480]", "image_size: [640]")).find("camera.image_size"),
            std::string::npos);
  EXPECT_NE(message(base + "  distortion: [0, 0]\n").find("expected 5 coefficients"), std::string::npos);
  EXPECT_NE(message(base + "  fxx: 1\n").find("fxx"), std::string::npos);
}

}  // namespace
}  // namespace spidar::vision
