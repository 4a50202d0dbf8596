// Camera calibration on synthetic data with known ground truth: the paper's three markers, PnP,
// and chessboard intrinsics from rendered board images (library and the calibrate-camera CLI).
#include <gtest/gtest.h>

#include "temp_path.hpp"
#ifdef SPIDAR_MR  // the calibrate-camera CLI test (a build with the app defines it)
#include "run_cli.hpp"
#endif

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sys/wait.h>
#include <unistd.h>

#include "spidar/core/units.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/chessboard.hpp"
#include "spidar/vision/markers.hpp"
#include "spidar/vision/pnp.hpp"
#include "spidar/vision/three_marker.hpp"

namespace spidar::vision {
namespace {

namespace fs = std::filesystem;

Camera true_camera() {
  Intrinsics in;
  in.fx = 558.0;
  in.fy = 556.0;
  in.cx = 324.0;
  in.cy = 236.0;
  in.distortion = {-0.12, 0.05, 0.0, 0.0, 0.0};
  // The rig pose, nudged so that nothing is axis-aligned by accident.
  const Pose X_WC = default_rig_camera().X_WC();
  const Pose nudge = Pose::FromRotationVector(Vec3(0.02, -0.015, 0.01), Vec3(0.004, -0.006, 0.003));
  return Camera(in, (X_WC * nudge).inverse());
}

struct PoseError {
  double position_m;  // camera centre
  double angle_deg;
};

PoseError pose_error(const Pose& X_CW, const Pose& X_CW_true) {
  const Pose a = X_CW.inverse(), b = X_CW_true.inverse();
  const double angle = Eigen::AngleAxisd(a.R * b.R.conjugate()).angle();
  return {(a.p - b.p).norm(), units::rad_to_deg(angle)};
}

// Markers on the SPIDAR-8 frame's working volume (world, m), all in view of the rig camera.
const std::vector<Vec3> kMarkers = {{-0.15, -0.08, 0.0}, {0.15, -0.08, 0.0}, {0.14, 0.12, 0.0},
                                    {-0.13, 0.11, 0.0},  {0.0, 0.05, 0.10},  {-0.05, -0.05, 0.08}};

TEST(ThreeMarker, PaperPlacementGivesThePaperFormulas) {
  // m1 at the world origin, m2 on the x axis, m3 in the xy plane: R = [x' y' z'], T = V1.
  const Camera cam = true_camera();
  const std::array<Vec3, 3> W = {Vec3(0, 0, 0), Vec3(0.2, 0, 0), Vec3(0.05, 0.15, 0)};
  std::array<MarkerPair, 3> m;
  for (int i = 0; i < 3; ++i) m[i] = {W[i], cam.to_camera(W[i])};
  const auto r = three_marker_extrinsics(m);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Vec3 V1 = m[0].p_C, V2 = m[1].p_C, V3 = m[2].p_C;
  const Vec3 x = V2 - V1;
  const Vec3 y = (V3 - V1) - (x.dot(V3 - V1) / x.dot(x)) * x;
  const Vec3 z = x.cross(y);
  Mat3 R;
  R << x.normalized(), y.normalized(), z.normalized();
  EXPECT_LT((r->X_CW.R.toRotationMatrix() - R).norm(), 1e-12);
  EXPECT_LT((r->X_CW.p - V1).norm(), 1e-12);
  const auto e = pose_error(r->X_CW, cam.X_CW());
  EXPECT_LT(e.position_m, 1e-3);
  EXPECT_LT(e.angle_deg, 0.1);
}

TEST(ThreeMarker, AnyPlacementNoiseFreeAndWithPixelNoise) {
  const Camera cam = true_camera();
  const std::array<Vec3, 3> W = {kMarkers[0], kMarkers[2], kMarkers[4]};
  std::array<MarkerPair, 3> m;
  for (int i = 0; i < 3; ++i) m[i] = {W[i], cam.to_camera(W[i])};
  const auto exact = three_marker_extrinsics(m);
  ASSERT_TRUE(exact.ok());
  const auto e0 = pose_error(exact->X_CW, cam.X_CW());
  EXPECT_LT(e0.position_m, 1e-3);
  EXPECT_LT(e0.angle_deg, 0.1);
  EXPECT_LT(exact->rms_m, 1e-12);

  // Camera coordinates measured as pixel (0.5 px noise per axis) + true depth.
  std::mt19937 rng(5);
  std::normal_distribution<double> px(0.0, 0.5);
  std::vector<double> pos, ang;
  for (int trial = 0; trial < 300; ++trial) {
    for (int i = 0; i < 3; ++i) {
      const Vec2 uv = cam.project(W[i]) + Vec2(px(rng), px(rng));
      m[i].p_C = cam.unproject_camera(uv, cam.depth(W[i]));
    }
    const auto r = three_marker_extrinsics(m);
    ASSERT_TRUE(r.ok());
    const auto e = pose_error(r->X_CW, cam.X_CW());
    pos.push_back(e.position_m * 1e3);
    ang.push_back(e.angle_deg);
  }
  std::sort(pos.begin(), pos.end());
  std::sort(ang.begin(), ang.end());
  ::testing::Test::RecordProperty("three_marker_noise05px_median_mm", std::to_string(pos[150]));
  ::testing::Test::RecordProperty("three_marker_noise05px_p95_mm", std::to_string(pos[285]));
  ::testing::Test::RecordProperty("three_marker_noise05px_median_deg", std::to_string(ang[150]));
  ::testing::Test::RecordProperty("three_marker_noise05px_p95_deg", std::to_string(ang[285]));
  std::printf("three-marker, 0.5 px noise: camera centre error median %.2f mm (p95 %.2f), "
              "rotation median %.3f deg (p95 %.3f)\n", pos[150], pos[285], ang[150], ang[285]);
  EXPECT_LT(pos[150], 10.0);
  EXPECT_LT(ang[150], 1.0);
}

TEST(ThreeMarker, RejectsCollinearOrCoincidentMarkers) {
  std::array<MarkerPair, 3> m = {MarkerPair{Vec3(0, 0, 0), Vec3(0, 0, 0.4)},
                                 MarkerPair{Vec3(0.1, 0, 0), Vec3(0.1, 0, 0.4)},
                                 MarkerPair{Vec3(0.2, 0.0005, 0), Vec3(0.2, 0.0005, 0.4)}};
  auto r = three_marker_extrinsics(m);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("non-collinear"), std::string::npos) << r.error().message;
  m[1] = m[0];
  EXPECT_NE(three_marker_extrinsics(m).error().message.find("0.01 m apart"), std::string::npos);
  m[1].p_W.x() = std::nan("");
  EXPECT_NE(three_marker_extrinsics(m).error().message.find("m2"), std::string::npos);
}

TEST(Pnp, NoiseFreeRecoversThePose) {
  const Camera cam = true_camera();
  for (std::size_t n : {4u, 6u}) {  // 4 coplanar markers, then 6 in a volume
    std::vector<Vec3> W(kMarkers.begin(), kMarkers.begin() + static_cast<long>(n));
    std::vector<Vec2> uv;
    for (const auto& p : W) uv.push_back(cam.project(p));
    const auto r = solve_pnp(cam.intrinsics(), W, uv);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const auto e = pose_error(r->X_CW, cam.X_CW());
    EXPECT_LT(e.position_m, 1e-3) << n << " markers";
    EXPECT_LT(e.angle_deg, 0.1) << n << " markers";
    EXPECT_LT(r->rms_px, 1e-6);
    std::printf("pnp, %zu markers, noise-free: %.2e m, %.2e deg, rms %.1e px\n", n, e.position_m,
                e.angle_deg, r->rms_px);
  }
}

TEST(Pnp, ErrorUnderHalfPixelNoise) {
  const Camera cam = true_camera();
  std::mt19937 rng(9);
  std::normal_distribution<double> px(0.0, 0.5);
  std::vector<double> pos, ang, rms;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Vec2> uv;
    for (const auto& p : kMarkers) uv.push_back(cam.project(p) + Vec2(px(rng), px(rng)));
    const auto r = solve_pnp(cam.intrinsics(), kMarkers, uv);
    ASSERT_TRUE(r.ok());
    const auto e = pose_error(r->X_CW, cam.X_CW());
    pos.push_back(e.position_m * 1e3);
    ang.push_back(e.angle_deg);
    rms.push_back(r->rms_px);
  }
  std::sort(pos.begin(), pos.end());
  std::sort(ang.begin(), ang.end());
  std::sort(rms.begin(), rms.end());
  RecordProperty("pnp6_noise05px_median_mm", std::to_string(pos[150]));
  RecordProperty("pnp6_noise05px_p95_mm", std::to_string(pos[285]));
  RecordProperty("pnp6_noise05px_median_deg", std::to_string(ang[150]));
  RecordProperty("pnp6_noise05px_p95_deg", std::to_string(ang[285]));
  RecordProperty("pnp6_noise05px_median_rms_px", std::to_string(rms[150]));
  std::printf("pnp, 6 markers, 0.5 px noise: camera centre error median %.2f mm (p95 %.2f), "
              "rotation median %.3f deg (p95 %.3f), reprojection rms median %.2f px\n",
              pos[150], pos[285], ang[150], ang[285], rms[150]);
  EXPECT_LT(pos[150], 10.0);
  EXPECT_LT(ang[150], 1.0);
}

TEST(Pnp, BadInputGivesClearErrors) {
  const Camera cam = true_camera();
  std::vector<Vec3> W(kMarkers.begin(), kMarkers.begin() + 3);
  std::vector<Vec2> uv;
  for (const auto& p : W) uv.push_back(cam.project(p));
  EXPECT_NE(solve_pnp(cam.intrinsics(), W, uv).error().message.find("at least 4"), std::string::npos);
  W.push_back(kMarkers[3]);
  EXPECT_NE(solve_pnp(cam.intrinsics(), W, uv).error().message.find("one pixel per marker"), std::string::npos);
  std::vector<Vec3> line = {{0, 0, 0}, {0.1, 0, 0}, {0.2, 0, 0}, {0.3, 0, 0}};
  std::vector<Vec2> uvl;
  for (const auto& p : line) uvl.push_back(cam.project(p));
  EXPECT_NE(solve_pnp(cam.intrinsics(), line, uvl).error().message.find("one line"), std::string::npos);
}

// --- chessboard images rendered through a known camera ------------------------------------

// Renders a 9x6 board (10x7 squares, 1-square white margin) seen by `cam` at board pose X_CB,
// with distortion, by inverse mapping (remap) at 2x and area downsampling.
class BoardRenderer {
 public:
  BoardRenderer(const Camera& cam, const ChessboardPattern& p) : cam_(cam), p_(p) {
    const int sq = 48;
    texture_ = cv::Mat((p.rows + 3) * sq, (p.cols + 3) * sq, CV_8UC1, cv::Scalar(250));
    for (int j = 0; j < p.rows + 1; ++j)
      for (int i = 0; i < p.cols + 1; ++i)
        if ((i + j) % 2 == 0)
          texture_(cv::Rect((i + 1) * sq, (j + 1) * sq, sq, sq)).setTo(cv::Scalar(15));
    sq_px_ = sq;
    // Rays of the 2x output pixels, undistorted once.
    const int W = 2 * cam.width(), H = 2 * cam.height();
    rays_.resize(static_cast<std::size_t>(W) * H);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        rays_[static_cast<std::size_t>(y) * W + x] =
            cam.undistort(Vec2((x + 0.5) / 2.0 - 0.5, (y + 0.5) / 2.0 - 0.5));
  }

  cv::Mat render(const Pose& X_CB) const {
    const int W = 2 * cam_.width(), H = 2 * cam_.height();
    cv::Mat mapx(H, W, CV_32FC1), mapy(H, W, CV_32FC1);
    const Mat3 Rt = X_CB.R.toRotationMatrix().transpose();
    const Vec3 Rt_t = Rt * X_CB.p;
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        const Vec2& xy = rays_[static_cast<std::size_t>(y) * W + x];
        const Vec3 r = Rt * Vec3(xy.x(), xy.y(), 1.0);
        const double lambda = Rt_t.z() / r.z();
        const Vec3 p_B = lambda * r - Rt_t;
        // Board point → texture centre coordinates: the first inner corner is at 2 squares.
        mapx.at<float>(y, x) = static_cast<float>((p_B.x() / p_.square + 2.0) * sq_px_ - 0.5);
        mapy.at<float>(y, x) = static_cast<float>((p_B.y() / p_.square + 2.0) * sq_px_ - 0.5);
        if (lambda <= 0) mapx.at<float>(y, x) = -1e6f;
      }
    }
    cv::Mat big, out;
    cv::remap(texture_, big, mapx, mapy, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar(90));
    cv::resize(big, out, cv::Size(cam_.width(), cam_.height()), 0, 0, cv::INTER_AREA);
    return out;
  }

 private:
  Camera cam_;
  ChessboardPattern p_;
  cv::Mat texture_;
  double sq_px_ = 48;
  std::vector<Vec2> rays_;
};

std::vector<Pose> board_poses(const ChessboardPattern& p) {
  const Vec3 centre_B((p.cols - 1) * p.square / 2, (p.rows - 1) * p.square / 2, 0);
  const double d = units::deg_to_rad(1.0);
  const struct { double ax, ay, az, x, y, z; } views[] = {
      {0, 0, 0, 0, 0, 0.42},          {30, 0, 5, 0.02, 0, 0.45},    {-30, 0, -5, -0.02, 0, 0.45},
      {0, 30, 0, 0, 0.02, 0.42},      {0, -30, 10, 0, -0.02, 0.42}, {20, 20, 0, -0.06, -0.04, 0.5},
      {-20, 25, -10, 0.06, 0.04, 0.5}, {25, -20, 15, 0.05, -0.05, 0.48}, {-25, -25, 0, -0.05, 0.05, 0.48},
      {10, -10, 30, 0.0, 0.0, 0.38},  {0, 0, -20, 0.07, 0.06, 0.55}, {15, 30, 5, -0.07, 0.05, 0.5}};
  std::vector<Pose> out;
  for (const auto& v : views) {
    const Quat R = Eigen::AngleAxisd(v.az * d, Vec3::UnitZ()) * Eigen::AngleAxisd(v.ay * d, Vec3::UnitY()) *
                   Eigen::AngleAxisd(v.ax * d, Vec3::UnitX());
    out.push_back({R, Vec3(v.x, v.y, v.z) - R * centre_B});
  }
  return out;
}

using spidar::test::temp_dir;

std::string write_board_images(const Camera& cam, const ChessboardPattern& p, const std::string& name) {
  const std::string dir = temp_dir(name);
  const BoardRenderer renderer(cam, p);
  int i = 0;
  for (const Pose& X_CB : board_poses(p)) {
    char file[64];
    std::snprintf(file, sizeof file, "/board_%02d.png", i++);
    EXPECT_TRUE(cv::imwrite(dir + file, renderer.render(X_CB)));
  }
  cv::imwrite(dir + "/empty.png", cv::Mat(cam.height(), cam.width(), CV_8UC1, cv::Scalar(128)));
  return dir;
}

void expect_intrinsics_near(const Intrinsics& got, const Intrinsics& want) {
  EXPECT_NEAR(got.fx / want.fx, 1.0, 0.005);
  EXPECT_NEAR(got.fy / want.fy, 1.0, 0.005);
  EXPECT_NEAR(got.cx, want.cx, 2.0);
  EXPECT_NEAR(got.cy, want.cy, 2.0);
  EXPECT_NEAR(got.distortion.k1, want.distortion.k1, 0.02);
  EXPECT_NEAR(got.distortion.k2, want.distortion.k2, 0.06);
  EXPECT_NEAR(got.distortion.p1, 0.0, 0.002);
  EXPECT_NEAR(got.distortion.p2, 0.0, 0.002);
  // And what matters: pixels of points in the working volume agree.
  const Camera a(got, Pose::Identity()), b(want, Pose::Identity());
  for (double x : {-0.15, 0.0, 0.15})
    for (double y : {-0.1, 0.0, 0.1}) EXPECT_LT((a.project(Vec3(x, y, 0.4)) - b.project(Vec3(x, y, 0.4))).norm(), 1.0);
}

TEST(Chessboard, IntrinsicsFromRenderedImages) {
  const Camera cam = true_camera();
  const ChessboardPattern p = parse_pattern("9x6", 0.025).value();
  const std::string dir = write_board_images(cam, p, "spidar_vision_boards");
  const auto r = calibrate_chessboard_folder(dir, p);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->used.size(), 12u);
  ASSERT_EQ(r->rejected.size(), 1u);
  EXPECT_NE(r->rejected[0].find("empty.png"), std::string::npos);
  const auto& in = r->calibration.intrinsics;
  std::printf("chessboard: rms %.3f px, fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f\n",
              r->calibration.rms_px, in.fx, in.fy, in.cx, in.cy, in.distortion.k1, in.distortion.k2);
  RecordProperty("chessboard_rms_px", std::to_string(r->calibration.rms_px));
  EXPECT_LT(r->calibration.rms_px, 0.3);
  expect_intrinsics_near(in, cam.intrinsics());
  fs::remove_all(dir);
}

TEST(Chessboard, PatternAndFolderErrors) {
  EXPECT_FALSE(parse_pattern("9-6", 0.025).ok());
  EXPECT_FALSE(parse_pattern("6x6", 0.025).ok());
  EXPECT_FALSE(parse_pattern("9x6", 25.0).ok());
  EXPECT_NE(calibrate_chessboard_folder("/nonexistent_dir", ChessboardPattern{}).error().message.find(
                "/nonexistent_dir: no such folder"),
            std::string::npos);
  const std::string dir = temp_dir("spidar_vision_noboards");
  cv::imwrite(dir + "/grey.png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(128)));
  const auto r = calibrate_chessboard_folder(dir, ChessboardPattern{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("in 0 of 1 images"), std::string::npos) << r.error().message;
  fs::remove_all(dir);
}

#ifdef SPIDAR_MR
spidar::test::Run run(const std::string& args) { return spidar::test::run_cli(args); }

TEST(CalibrateCameraCli, CalibratesFromRenderedBoardsAndMarkers) {
  const Camera cam = true_camera();
  const ChessboardPattern p = parse_pattern("9x6", 0.025).value();
  const std::string dir = write_board_images(cam, p, "spidar_vision_cli_boards");
  // Markers seen by the fixed rig camera (exact pixels).
  const std::string files = spidar::test::temp_dir("spidar_vision_cli_files");
  const std::string markers = files + "/markers.yaml";
  {
    std::ofstream f(markers);
    f << "markers:\n";
    for (const auto& m : kMarkers) {
      const Vec2 uv = cam.project(m);
      f << "  - {world: [" << m.x() << ", " << m.y() << ", " << m.z() << "], pixel: [" << uv.x() << ", " << uv.y() << "]}\n";
    }
  }
  const std::string out = files + "/camera_out.yaml";
  const auto r = run("calibrate-camera --images " + dir + " --pattern 9x6 --square 0.025 --markers " +
                     markers + " --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"boards_found\":12"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"method\":\"pnp\""), std::string::npos) << r.out;
  const auto f = load_camera_file(out);
  expect_intrinsics_near(f.camera.intrinsics(), cam.intrinsics());
  const auto e = pose_error(f.camera.X_CW(), cam.X_CW());
  std::printf("calibrate-camera CLI: camera centre error %.2f mm, rotation %.3f deg, marker rms %.3f px\n",
              e.position_m * 1e3, e.angle_deg, f.calibration.extrinsics_rms_px.value_or(-1));
  RecordProperty("cli_pose_error_mm", std::to_string(e.position_m * 1e3));
  RecordProperty("cli_pose_error_deg", std::to_string(e.angle_deg));
  EXPECT_LT(e.position_m, 0.005);
  EXPECT_LT(e.angle_deg, 0.5);

  // Calibrating again keeps the previous camera file beside the new one.
  std::ifstream first_in(out);
  const std::string first((std::istreambuf_iterator<char>(first_in)), {});
  const auto again = run("calibrate-camera --images " + dir + " --pattern 9x6 --square 0.025 --markers " +
                         markers + " --out " + out);
  ASSERT_EQ(again.code, 0) << again.err;
  const auto at = again.out.find("\"backup\":\"");
  ASSERT_NE(at, std::string::npos) << again.out;
  const std::string backup = again.out.substr(at + 10, again.out.find('"', at + 10) - (at + 10));
  EXPECT_NE(backup.find(".bak-"), std::string::npos) << backup;
  std::ifstream backup_in(backup);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(backup_in)), {}), first);
  fs::remove(backup);

  // Extrinsics alone (no --images): the paper's three markers in camera coordinates, the
  // intrinsics kept from --base.
  const std::string three = dir + "/../spidar_vision_three_" + std::to_string(getpid()) + ".yaml";
  {
    std::ofstream file(three);
    file << "markers:\n";
    for (int k = 0; k < 3; ++k) {
      const Vec3& m = kMarkers[k];
      const Vec3 c = cam.to_camera(m);
      file << "  - {world: [" << m.x() << ", " << m.y() << ", " << m.z() << "], camera: [" << c.x() << ", " << c.y()
        << ", " << c.z() << "]}\n";
    }
  }
  const std::string out3 = files + "/camera_three.yaml";
  const auto ex = run("calibrate-camera --markers " + three + " --base " + out + " --out " + out3);
  ASSERT_EQ(ex.code, 0) << ex.err;
  EXPECT_NE(ex.out.find("\"method\":\"three-marker\""), std::string::npos) << ex.out;
  const auto f3 = load_camera_file(out3);
  EXPECT_EQ(f3.camera.intrinsics().fx, f.camera.intrinsics().fx);  // kept from --base, exactly
  EXPECT_EQ(f3.camera.intrinsics().cx, f.camera.intrinsics().cx);
  const auto e3 = pose_error(f3.camera.X_CW(), cam.X_CW());
  EXPECT_LT(e3.position_m, 1e-4);
  EXPECT_LT(e3.angle_deg, 0.01);
  fs::remove(three);
  fs::remove(out3);
  auto neither = run("calibrate-camera --out " + out3);
  EXPECT_EQ(neither.code, 2);
  EXPECT_NE(neither.err.find("--images or --markers"), std::string::npos) << neither.err;

  // Bad input: exit code 2 and a message naming the problem.
  auto bad = run("calibrate-camera --images " + dir + " --pattern 9x9 --out " + out);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--pattern"), std::string::npos) << bad.err;
  auto missing = run("calibrate-camera --images /nonexistent_images --out " + out);
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("/nonexistent_images: no such folder"), std::string::npos) << missing.err;
  fs::remove_all(dir);
  fs::remove(markers);
  fs::remove(out);
}
#endif

TEST(Markers, ParseAndThreeMarkerFromFile) {
  const Camera cam = true_camera();
  std::string text = "markers:\n";
  for (int i : {0, 2, 4}) {
    const Vec3 c = cam.to_camera(kMarkers[i]);
    const Vec3& w = kMarkers[i];
    text += "  - {world: [" + std::to_string(w.x()) + ", " + std::to_string(w.y()) + ", " + std::to_string(w.z()) +
            "], camera: [" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + "]}\n";
  }
  const auto set = parse_markers(core::ConfigNode::Parse(text, "m.yaml"));
  EXPECT_FALSE(set.by_pixel);
  const auto r = calibrate_extrinsics(cam.intrinsics(), set);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(r->method, "three-marker");
  EXPECT_LT(pose_error(r->X_CW, cam.X_CW()).position_m, 1e-5);  // the file rounds to 1e-6 m
  try {
    parse_markers(core::ConfigNode::Parse("markers:\n  - {world: [0,0,0], pixel: [1,2]}\n  - {world: [1,0,0], "
                                          "camera: [1,2,3]}\n  - {world: [0,1,0], pixel: [1,2]}\n", "m.yaml"));
    FAIL() << "mixed markers accepted";
  } catch (const core::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("m.yaml:3: markers[1]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace spidar::vision
