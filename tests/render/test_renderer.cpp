// The GL renderer against the camera model: silhouettes and depths of known shapes, without
// golden images.
#include <gtest/gtest.h>

#include "render_test_cameras.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "gl_test_support.hpp"
#include "spidar/core/units.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/renderer.hpp"

namespace spidar::render {
namespace {

using test::gl_context;

Shape box_shape(const Pose& X_WB, const Vec3& half, std::array<float, 4> rgba = {0.2f, 0.6f, 0.9f, 1.f}) {
  Shape s;
  s.type = Shape::Type::kBox;
  s.X_WS = X_WB;
  s.size = half;
  s.rgba = rgba;
  return s;
}

/// Depth z_C of the first hit of the ray through pixel uv with the box, or NaN if it misses.
double ray_box_depth(const vision::Camera& cam, const Pose& X_WB, const Vec3& half, const Vec2& uv) {
  const Pose X_BW = X_WB.inverse();
  const Vec3 o = X_BW * cam.X_WC().p;
  const Vec3 d = X_BW.R * cam.ray_direction_W(uv);
  double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (std::abs(o[k]) > half[k]) return std::nan("");
      continue;
    }
    double a = (-half[k] - o[k]) / d[k], b = (half[k] - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 > t1 || t1 <= 0) return std::nan("");
  return cam.depth(X_WB * (o + t0 * d));
}

using testing::odd_camera;

class BoxProjection : public ::testing::TestWithParam<int> {};

TEST_P(BoxProjection, CornersWithinOnePixelAndDepthWithinOneMillimetre) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = GetParam() == 0 ? vision::default_rig_camera() : odd_camera();
  const Pose X_WB{Quat(Eigen::AngleAxisd(0.5, Vec3(0.3, -0.2, 1.0).normalized())),
                  Vec3(0.01, 0.02, 0.0)};
  const Vec3 half(0.04, 0.03, 0.02);
  SceneSnapshot scene;
  scene.shapes.push_back(box_shape(X_WB, half));
  auto renderer = Renderer::create(*gl_context(), cam.width(), cam.height()).value();
  ASSERT_TRUE(renderer->render(scene, cam).ok());
  RenderTargets t;
  ASSERT_TRUE(renderer->read(&t).ok());
  ASSERT_EQ(t.depth.cols, cam.width());
  ASSERT_EQ(t.depth.rows, cam.height());

  // The silhouette is the convex hull of the projected corners.
  std::vector<cv::Point2f> corners;
  for (int i = 0; i < 8; ++i) {
    const Vec3 s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    const Vec2 uv = cam.project(X_WB * Vec3(s.cwiseProduct(half)));
    corners.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(corners, hull);
  int covered = 0, wrong = 0, strict_wrong = 0, depth_checked = 0;
  double worst_depth_mm = 0;
  for (int v = 0; v < cam.height(); ++v) {
    for (int u = 0; u < cam.width(); ++u) {
      const bool on = std::isfinite(t.depth.at<float>(v, u));
      const double inside = cv::pointPolygonTest(hull, cv::Point2f(float(u), float(v)), true);
      if (on) ++covered;
      if ((inside > 1.0 && !on) || (inside < -1.0 && on)) ++wrong;
      if ((inside > 0.05 && !on) || (inside < -0.05 && on)) ++strict_wrong;
      if (on && inside > 1.0) {
        const double expected = ray_box_depth(cam, X_WB, half, Vec2(u, v));
        ASSERT_TRUE(std::isfinite(expected)) << "pixel " << u << "," << v;
        worst_depth_mm = std::max(worst_depth_mm, 1e3 * std::abs(t.depth.at<float>(v, u) - expected));
        ++depth_checked;
      }
      EXPECT_EQ(t.hand_id.at<std::uint8_t>(v, u), 0);
      EXPECT_FALSE(std::isfinite(t.hand_depth.at<float>(v, u)));
    }
  }
  EXPECT_GT(covered, 500);
  EXPECT_EQ(wrong, 0) << "pixels more than 1 px inside the projected hull but empty, or outside "
                         "but covered";
  EXPECT_GT(depth_checked, 400);
  EXPECT_LT(worst_depth_mm, 1.0);
  // Pixel-centre sampling is exact, so the same holds at a twentieth of a pixel: a half-pixel
  // slip in the OpenCV → GL convention would fail here though it passes at 1 px.
  EXPECT_EQ(strict_wrong, 0) << "pixels more than 0.05 px inside/outside the hull misclassified";
}

INSTANTIATE_TEST_SUITE_P(Cameras, BoxProjection, ::testing::Values(0, 1));

TEST(Renderer, ReportsItsGl) {
  SPIDAR_REQUIRE_GL();
  EXPECT_EQ(gl_context()->kind(), ContextKind::kHeadless);
  EXPECT_FALSE(gl_context()->gl_renderer().empty());
  std::cout << "GL_RENDERER: " << gl_context()->gl_renderer()
            << ", GL_VERSION: " << gl_context()->gl_version() << "\n";
}

// A capsule's outline (the hand id target) is as wide as the capsule, whatever its roll about its
// own axis: the template is a polygon, and its vertices sit far enough out that its width,
// averaged over the roll, is the circle's (primitive_mesh.hpp). The capsule lies across the line
// of sight, tilted 10° in the image so that its edges cross the pixel rows; its width is the hand
// pixels per column over its middle, times the cosine of the tilt, against the round capsule's
// outline in perspective. Measured: 1.005 on average (0.994 with the polygon's vertices on the
// unit circle), 1.0 % at worst.
TEST(Renderer, ACapsulesOutlineIsAsWideAsTheCapsuleWhateverItsRoll) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  auto renderer = Renderer::create(*gl_context()).value();
  const Mat3 R_WC = cam.X_WC().R.toRotationMatrix();
  const double tilt = 10.0 * units::kPi / 180.0, radius = 0.008, half_length = 0.04;
  const Vec3 centre = Vec3::Zero();
  const Vec3 axis = std::cos(tilt) * R_WC.col(0) + std::sin(tilt) * R_WC.col(1);  // image u, then v
  const double depth = cam.depth(centre);
  // The round capsule's outline there, in perspective: its silhouette generators lie a radius
  // either side of the axis, across the ray to it (off the optical axis it looks a little wider
  // than 2 r f / depth).
  const Vec3 side = radius * axis.cross(centre - cam.X_WC().p).normalized();
  const Vec2 along_px = (cam.project(centre + axis * 0.01) - cam.project(centre)).normalized();
  const double expected = std::abs((cam.project(centre + side) - cam.project(centre - side)).dot(Vec2(-along_px.y(), along_px.x())));
  const Vec2 uc = cam.project(centre);
  const double half_span_px = 0.5 * half_length * cam.intrinsics().fx / depth;  // the middle half
  double sum = 0, worst = 0;
  constexpr int kRolls = 8;
  for (int k = 0; k < kRolls; ++k) {
    const double roll = (units::kPi / 12.0) * k / kRolls;  // a 12-gon's whole period is π/6; half by symmetry
    Shape s = capsule_shape(centre - half_length * axis, centre + half_length * axis, radius);
    s.X_WS.R = s.X_WS.R * Quat(Eigen::AngleAxisd(roll, Vec3::UnitZ()));
    s.hand = 1;
    s.finger = 1;
    SceneSnapshot scene;
    scene.shapes.push_back(s);
    ASSERT_TRUE(renderer->render(scene, cam).ok());
    RenderTargets t;
    ASSERT_TRUE(renderer->read(&t, kHandId).ok());
    double pixels = 0;
    int columns = 0;
    for (int u = static_cast<int>(uc.x() - half_span_px); u <= static_cast<int>(uc.x() + half_span_px); ++u, ++columns)
      pixels += cv::countNonZero(t.hand_id.col(u));
    const double width = pixels / columns * std::cos(tilt);
    sum += width / expected;
    worst = std::max(worst, std::abs(width / expected - 1.0));
  }
  EXPECT_NEAR(sum / kRolls, 1.0, 0.01) << "expected " << expected << " px";
  EXPECT_LT(worst, 0.025);
}

TEST(Renderer, HandTargetsAndOcclusion) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  const Vec3 half(0.03, 0.03, 0.03);
  auto renderer = Renderer::create(*gl_context()).value();
  const Vec3 toward_camera = (cam.X_WC().p - Vec3::Zero()).normalized();
  const Vec2 centre = cam.project(Vec3::Zero());
  const int u = static_cast<int>(std::lround(centre.x())), v = static_cast<int>(std::lround(centre.y()));
  for (bool in_front : {true, false}) {
    SceneSnapshot scene;
    scene.shapes.push_back(box_shape(Pose{}, half, {0.1f, 0.2f, 0.9f, 1.f}));
    // A finger across the line of sight to the box centre: 8 cm toward the camera, or behind.
    const Vec3 c = toward_camera * (in_front ? 0.08 : -0.08);
    Shape finger = capsule_shape(c - Vec3(0.03, 0, 0), c + Vec3(0.03, 0, 0), 0.008);
    finger.hand = 1;
    finger.finger = 2;
    scene.shapes.push_back(finger);
    for (HandDrawMode mode : {HandDrawMode::kHidden, HandDrawMode::kVisible}) {
      RenderParams params;
      params.hands = mode;
      ASSERT_TRUE(renderer->render(scene, cam, params).ok());
      RenderTargets t;
      ASSERT_TRUE(renderer->read(&t).ok());
      const HandId id = decode_hand_id(t.hand_id.at<std::uint8_t>(v, u));
      EXPECT_EQ(id.hand, 1);
      EXPECT_EQ(id.finger, 2);
      const double box_centre_depth = cam.depth(Vec3::Zero());
      const float depth = t.depth.at<float>(v, u), hand_depth = t.hand_depth.at<float>(v, u);
      EXPECT_LT(depth, box_centre_depth);  // the box's near face, in `depth` either way
      EXPECT_NEAR(hand_depth, cam.depth(c) - 0.008, 0.002);
      EXPECT_EQ(hand_depth < depth, in_front);
      const cv::Vec3b bgr = t.colour.at<cv::Vec3b>(v, u);
      const bool looks_like_box = bgr[0] > bgr[2] + 40;  // the box is blue, the hand skin
      EXPECT_EQ(looks_like_box, !(in_front && mode == HandDrawMode::kVisible))
          << "in_front " << in_front << " visible " << (mode == HandDrawMode::kVisible);
      // The hands' box: around every hand pixel, and unknown when the hand ids were not read.
      ASSERT_TRUE(t.hand_box.has_value());
      EXPECT_EQ(*t.hand_box, cv::boundingRect(t.hand_id));
      EXPECT_EQ(*t.hand_box, cv::boundingRect(t.hand_depth < std::numeric_limits<float>::infinity()));
      EXPECT_GT(t.hand_box->area(), 100);
      ASSERT_TRUE(renderer->read(&t, kColour | kDepth | kHandDepth).ok());
      EXPECT_FALSE(t.hand_box.has_value());
    }
  }
}

TEST(Renderer, ColourIsReadAsBgrBytes) {
  SPIDAR_REQUIRE_GL();
  // Unlit colours (ambient 1): the box and the background must come back as the bytes
  // round(255 · rgb) in B, G, R order, whatever buffer the read-back is given.
  const vision::Camera cam = vision::default_rig_camera();
  auto renderer = Renderer::create(*gl_context()).value();
  SceneSnapshot scene;
  scene.shapes.push_back(box_shape(Pose{}, Vec3(0.03, 0.03, 0.03), {0.2f, 0.6f, 0.8f, 1.f}));
  RenderParams params;
  params.ambient = 1.f;
  params.background_rgb = {1.f, 0.4f, 0.f};
  ASSERT_TRUE(renderer->render(scene, cam, params).ok());
  const Vec2 centre = cam.project(Vec3::Zero());
  const int u = static_cast<int>(std::lround(centre.x())), v = static_cast<int>(std::lround(centre.y()));
  RenderTargets fresh, reused;
  reused.colour = cv::Mat(7, 5, CV_8UC3, cv::Scalar(1, 2, 3));
  for (RenderTargets* t : {&fresh, &reused}) {
    ASSERT_TRUE(renderer->read(t, kColour).ok());
    ASSERT_EQ(t->colour.type(), CV_8UC3);
    ASSERT_EQ(t->colour.size(), cv::Size(cam.width(), cam.height()));
    EXPECT_EQ(t->colour.at<cv::Vec3b>(v, u), cv::Vec3b(204, 153, 51));
    EXPECT_EQ(t->colour.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 102, 255));
    EXPECT_TRUE(t->depth.empty());  // only the colour was asked for
  }
}

TEST(Renderer, MeshesPlanesSpheresAndBadShapes) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  auto meshes = std::make_shared<std::vector<MeshData>>();
  MeshData tetra;
  tetra.name = "tetra";
  tetra.vertices = {0, 0, 0.03f, 0.03f, 0, -0.01f, -0.015f, 0.026f, -0.01f, -0.015f, -0.026f, -0.01f};
  tetra.faces = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
  meshes->push_back(tetra);
  SceneSnapshot scene;
  scene.meshes = meshes;
  Shape tet;
  tet.type = Shape::Type::kMesh;
  tet.mesh = 0;
  tet.X_WS.p = Vec3(0.05, 0, 0);
  scene.shapes.push_back(tet);
  Shape sphere;
  sphere.type = Shape::Type::kSphere;
  sphere.size = Vec3(0.02, 0, 0);
  sphere.X_WS.p = Vec3(-0.05, 0, 0);
  scene.shapes.push_back(sphere);
  Shape plane;
  plane.type = Shape::Type::kPlane;
  plane.X_WS.p = Vec3(0, 0, -0.05);
  scene.shapes.push_back(plane);
  Shape bad = sphere;
  bad.X_WS.p = Vec3(std::nan(""), 0, 0);
  scene.shapes.push_back(bad);
  Shape bad_mesh = tet;
  bad_mesh.mesh = 7;
  scene.shapes.push_back(bad_mesh);

  auto renderer = Renderer::create(*gl_context()).value();
  ASSERT_TRUE(renderer->render(scene, cam).ok());
  RenderTargets t;
  ASSERT_TRUE(renderer->read(&t, kDepth | kColour).ok());
  EXPECT_TRUE(t.hand_depth.empty());  // not asked for
  // Sphere: the depth at its centre pixel is its near surface, within the tessellation error.
  const Vec2 s_uv = cam.project(sphere.X_WS.p);
  const float ds = t.depth.at<float>(int(std::lround(s_uv.y())), int(std::lround(s_uv.x())));
  EXPECT_NEAR(ds, cam.depth(sphere.X_WS.p) - 0.02, 0.002);
  const Vec2 t_uv = cam.project(tet.X_WS.p);
  EXPECT_LT(t.depth.at<float>(int(std::lround(t_uv.y())), int(std::lround(t_uv.x()))),
            cam.depth(tet.X_WS.p) + 0.03);
  // The plane fills the lower image (5 m "infinite" extent); nothing is NaN.
  EXPECT_TRUE(std::isfinite(t.depth.at<float>(cam.height() - 1, cam.width() / 2)));
  cv::Mat nan_mask = t.depth != t.depth;
  EXPECT_EQ(cv::countNonZero(nan_mask), 0);
}

// A cube mesh in world coordinates (X_WS = identity), with or without its own normals.
MeshData cube_mesh(const Vec3& c, double half, bool with_normals) {
  MeshData m;
  m.name = "cube";
  for (int i = 0; i < 8; ++i) {
    const Vec3 corner(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    const Vec3 p = c + half * corner;
    for (int k = 0; k < 3; ++k) m.vertices.push_back(static_cast<float>(p[k]));
    if (with_normals)
      for (int k = 0; k < 3; ++k) m.normals.push_back(static_cast<float>(corner.normalized()[k]));
  }
  // Corners: bit 0 = +x, bit 1 = +y, bit 2 = +z; counter-clockwise from outside.
  m.faces = {0, 3, 1, 0, 2, 3, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
             3, 2, 6, 3, 6, 7, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

// Hand pixels (id > 0) within 6 px of the projection of p.
int hand_pixels_near(const RenderTargets& t, const vision::Camera& cam, const Vec3& p) {
  const Vec2 uv = cam.project(p);
  const cv::Rect r(int(uv.x()) - 6, int(uv.y()) - 6, 13, 13);
  return cv::countNonZero(t.hand_id(r & cv::Rect(0, 0, t.hand_id.cols, t.hand_id.rows)) > 0);
}

TEST(Renderer, ChangedMeshesAreUploadedAgainWhenTheirVersionChanges) {
  SPIDAR_REQUIRE_GL();
  const vision::Camera cam = vision::default_rig_camera();
  const Vec3 a(-0.05, 0.0, 0.03), b(0.06, 0.02, 0.03);
  for (bool with_normals : {true, false}) {
    SCOPED_TRACE(with_normals ? "own normals" : "derived normals");
    auto meshes = std::make_shared<std::vector<MeshData>>();
    meshes->push_back(cube_mesh(a, 0.01, with_normals));
    SceneSnapshot scene;
    scene.meshes = meshes;
    Shape s;
    s.type = Shape::Type::kMesh;
    s.mesh = 0;
    s.hand = 1;
    s.finger = 2;
    scene.shapes.push_back(s);
    auto renderer = Renderer::create(*gl_context()).value();
    RenderTargets t;
    auto draw = [&] {
      ASSERT_TRUE(renderer->render(scene, cam).ok());
      ASSERT_TRUE(renderer->read(&t, kHandId).ok());
    };
    draw();
    EXPECT_EQ(hand_pixels_near(t, cam, a), 169);
    EXPECT_EQ(hand_pixels_near(t, cam, b), 0);
    EXPECT_EQ(t.hand_id.at<std::uint8_t>(cv::Point(cam.project(a).cast<int>().x(), cam.project(a).cast<int>().y())),
              encode_hand_id(1, 2));
    // Moved in place without a new version: the renderer keeps what it uploaded.
    (*meshes)[0].vertices = cube_mesh(b, 0.01, with_normals).vertices;
    draw();
    EXPECT_EQ(hand_pixels_near(t, cam, a), 169);
    EXPECT_EQ(hand_pixels_near(t, cam, b), 0);
    // A new version: drawn where it is now (same sizes: updated in place).
    ++(*meshes)[0].version;
    draw();
    EXPECT_EQ(hand_pixels_near(t, cam, a), 0);
    EXPECT_EQ(hand_pixels_near(t, cam, b), 169);
    // A new version with more triangles (two cubes): new buffer stores.
    MeshData two = cube_mesh(b, 0.01, with_normals);
    const MeshData other = cube_mesh(a, 0.01, with_normals);
    const int n = static_cast<int>(two.vertices.size() / 3);
    two.vertices.insert(two.vertices.end(), other.vertices.begin(), other.vertices.end());
    two.normals.insert(two.normals.end(), other.normals.begin(), other.normals.end());
    for (int f : other.faces) two.faces.push_back(f + n);
    two.version = (*meshes)[0].version + 1;
    (*meshes)[0] = two;
    draw();
    EXPECT_EQ(hand_pixels_near(t, cam, a), 169);
    EXPECT_EQ(hand_pixels_near(t, cam, b), 169);
  }
}

/// Pixels where two renders' targets differ (any of the four).
int differing_pixels(const RenderTargets& a, const RenderTargets& b) {
  cv::Mat diff = a.hand_id != b.hand_id;
  cv::Mat c;
  cv::compare(a.depth, b.depth, c, cv::CMP_NE);
  diff |= c;
  cv::compare(a.hand_depth, b.hand_depth, c, cv::CMP_NE);
  diff |= c;
  cv::Mat colour_diff;
  cv::absdiff(a.colour, b.colour, colour_diff);
  cv::cvtColor(colour_diff, c, cv::COLOR_BGR2GRAY);
  diff |= c > 0;
  return cv::countNonZero(diff);
}

TEST(Renderer, CachedStaticWorldGivesTheSameTargetsAndFollowsChanges) {
  SPIDAR_REQUIRE_GL();
  // A table (the world body's plane), a static block on it, a moving box sunk into the table (so
  // the copied depth buffer must hide its lower part) and a hand capsule in front of it.
  SceneSnapshot scene;
  Shape table;
  table.type = Shape::Type::kPlane;
  table.size = Vec3(0.3, 0.3, 0);
  table.body = 0;
  table.rgba = {0.6f, 0.5f, 0.4f, 1.f};
  scene.shapes.push_back(table);
  Shape block = box_shape(Pose{Quat::Identity(), Vec3(-0.06, 0.04, 0.02)}, Vec3(0.02, 0.02, 0.02),
                          {0.9f, 0.9f, 0.1f, 1.f});
  block.body = 0;
  scene.shapes.push_back(block);
  Shape moving = box_shape(Pose{Quat::Identity(), Vec3(0.02, 0.0, 0.01)}, Vec3(0.03, 0.03, 0.03));
  moving.body = 3;
  scene.shapes.push_back(moving);
  Shape finger = capsule_shape(Vec3(-0.02, -0.02, 0.06), Vec3(0.05, 0.01, 0.07), 0.008);
  finger.hand = 0;
  finger.finger = 1;
  scene.shapes.push_back(finger);

  auto cached = Renderer::create(*gl_context()).value();
  auto reference = Renderer::create(*gl_context()).value();
  RenderParams uncached;
  uncached.cache_static = false;
  auto compare = [&](const SceneSnapshot& sc, const vision::Camera& cam, RenderParams params,
                     const char* what) {
    RenderParams ref = params;
    ref.cache_static = false;
    RenderTargets a, b;
    ASSERT_TRUE(cached->render(sc, cam, params).ok());
    ASSERT_TRUE(cached->read(&a).ok());
    ASSERT_TRUE(reference->render(sc, cam, ref).ok());
    ASSERT_TRUE(reference->read(&b).ok());
    ASSERT_GT(cv::countNonZero(b.depth < 1e3f), 1000) << what << ": the scene must be in view";
    EXPECT_EQ(differing_pixels(a, b), 0) << what;
  };
  const vision::Camera cam = vision::default_rig_camera();
  // A moving mesh (a tetrahedron) and a moving capsule too: the cache is copied back only where
  // the last frame's objects may have drawn (their bounding boxes' projections).
  auto meshes = std::make_shared<std::vector<MeshData>>();
  MeshData tetra;
  tetra.vertices = {0, 0, 0.03f, 0.03f, 0, -0.01f, -0.015f, 0.026f, -0.01f, -0.015f, -0.026f, -0.01f};
  tetra.faces = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
  meshes->push_back(tetra);
  scene.meshes = meshes;
  Shape tet;
  tet.type = Shape::Type::kMesh;
  tet.mesh = 0;
  tet.body = 4;
  tet.X_WS.p = Vec3(-0.08, -0.05, 0.01);
  scene.shapes.push_back(tet);
  Shape rod = capsule_shape(Vec3(0.06, -0.06, 0.01), Vec3(0.1, -0.02, 0.02), 0.006);
  rod.body = 5;
  scene.shapes.push_back(rod);
  compare(scene, cam, {}, "first frame (cache drawn)");
  compare(scene, cam, {}, "second frame (cache copied)");
  scene.shapes[2].X_WS.p.x() += 0.02;  // the moving box moves: the cache still holds
  compare(scene, cam, {}, "moved object");
  scene.shapes[4].X_WS.p += Vec3(0.12, 0.07, 0.0);  // the mesh and the capsule move far
  scene.shapes[4].X_WS.R = Eigen::AngleAxisd(1.0, Vec3::UnitZ());
  scene.shapes[5].X_WS.p.x() -= 0.15;
  compare(scene, cam, {}, "moved mesh and capsule");
  SceneSnapshot static_and_hands = scene;  // no moving object: nothing to copy back next frame
  static_and_hands.shapes.erase(static_and_hands.shapes.begin() + 2);
  static_and_hands.shapes.resize(3);
  compare(static_and_hands, cam, {}, "no moving objects");
  compare(scene, cam, {}, "objects back");
  // A rod from behind the camera to 30 cm in front of it, beside the optical axis: a bound
  // through the camera plane is the whole image.
  SceneSnapshot at_camera = scene;
  const Pose X_WR{Quat(cam.X_WC().R), cam.X_WC() * Vec3(0.04, 0.03, 0.1)};
  at_camera.shapes.push_back(box_shape(X_WR, Vec3(0.01, 0.01, 0.2)));
  at_camera.shapes.back().body = 6;
  compare(at_camera, cam, {}, "object through the camera plane");
  compare(scene, cam, {}, "after the object around the camera");
  RenderParams visible_same_light;
  visible_same_light.hands = HandDrawMode::kVisible;
  compare(scene, cam, visible_same_light, "visible hands (drawn over the copied world)");
  compare(scene, cam, {}, "hidden again");
  scene.shapes[1].X_WS.p.y() -= 0.03;  // the static block moves: the cache must be redrawn
  compare(scene, cam, {}, "moved static block");
  compare(scene, odd_camera(), {}, "another camera and image size");
  compare(scene, cam, {}, "back to the first camera");
  RenderParams visible;
  visible.hands = HandDrawMode::kVisible;
  visible.ambient = 0.6f;
  compare(scene, cam, visible, "visible hands, other light");
  // Without the static shapes, nothing is copied: the targets are cleared as before.
  SceneSnapshot moving_only = scene;
  moving_only.shapes.erase(moving_only.shapes.begin(), moving_only.shapes.begin() + 2);
  compare(moving_only, cam, {}, "no static shapes");
}

TEST(Renderer, EachFrameStartsFromClearedTargets) {
  SPIDAR_REQUIRE_GL();
  // A renderer that drew hands (with and without a static world, visible and hidden, its targets
  // read back or not: the renderer resets only where it saw hands when it knows) must give a
  // next frame with other hands, or none, the targets of a renderer that never drew anything:
  // nothing of the earlier hands may remain in hand depth, hand id or the depth buffer.
  // Three fingers at x .. x + 5 cm; the first 2 cm under the table, whose depth buffer must not
  // hide it from the hand targets.
  auto hands_at = [](double x) {
    SceneSnapshot s;
    for (int f = 0; f < 3; ++f) {
      const double z = f == 0 ? -0.02 : 0.05;
      Shape finger = capsule_shape(Vec3(x, -0.03 + 0.025 * f, z), Vec3(x + 0.05, -0.02 + 0.025 * f, z + 0.01), 0.009);
      finger.hand = f % 2;
      finger.finger = f;
      s.shapes.push_back(finger);
    }
    return s;
  };
  Shape table;
  table.type = Shape::Type::kPlane;
  table.size = Vec3(0.3, 0.3, 0);
  table.body = 0;
  Shape moving = box_shape(Pose{Quat::Identity(), Vec3(0.02, 0.0, 0.01)}, Vec3(0.03, 0.03, 0.03));
  moving.body = 3;
  const vision::Camera cam = vision::default_rig_camera();
  auto used = Renderer::create(*gl_context()).value();
  for (bool with_table : {true, false}) {
    for (HandDrawMode mode : {HandDrawMode::kHidden, HandDrawMode::kVisible}) {
     for (unsigned read_before : {0u, unsigned{kHandId}, unsigned{kAllTargets}}) {
      RenderParams params;
      params.hands = mode;
      SceneSnapshot before = hands_at(-0.06), after = hands_at(0.03), none;
      for (SceneSnapshot* s : {&before, &after, &none}) {
        if (with_table) s->shapes.push_back(table);
        s->shapes.push_back(moving);
      }
      ASSERT_TRUE(used->render(before, cam, params).ok());
      if (read_before != 0) {
        RenderTargets seen;
        ASSERT_TRUE(used->read(&seen, read_before).ok());
      }
      for (const SceneSnapshot* next : {&after, &none}) {
        auto fresh = Renderer::create(*gl_context()).value();
        RenderTargets a, b;
        ASSERT_TRUE(used->render(*next, cam, params).ok());
        ASSERT_TRUE(used->read(&a).ok());
        ASSERT_TRUE(fresh->render(*next, cam, params).ok());
        ASSERT_TRUE(fresh->read(&b).ok());
        EXPECT_EQ(differing_pixels(a, b), 0) << "table " << with_table << " visible "
                                             << (mode == HandDrawMode::kVisible) << " read "
                                             << read_before << " hands " << (next == &after);
        if (next == &after) {
          EXPECT_GT(cv::countNonZero(a.hand_id), 1000);
        }
      }
     }
    }
  }
  // Hands only, no scene: the same through a change of image size.
  ASSERT_TRUE(used->render(hands_at(-0.06), odd_camera()).ok());
  ASSERT_TRUE(used->render(hands_at(0.03), cam).ok());
  auto fresh = Renderer::create(*gl_context()).value();
  ASSERT_TRUE(fresh->render(hands_at(0.03), cam).ok());
  RenderTargets a, b;
  ASSERT_TRUE(used->read(&a).ok());
  ASSERT_TRUE(fresh->read(&b).ok());
  EXPECT_EQ(differing_pixels(a, b), 0) << "after a resize";
}

TEST(Renderer, ResizesToTheCamera) {
  SPIDAR_REQUIRE_GL();
  auto renderer = Renderer::create(*gl_context(), 64, 48).value();
  const vision::Camera cam = odd_camera();
  ASSERT_TRUE(renderer->render(SceneSnapshot{}, cam).ok());
  RenderTargets t;
  ASSERT_TRUE(renderer->read(&t).ok());
  EXPECT_EQ(t.colour.cols, 321);
  EXPECT_EQ(t.colour.rows, 243);
  EXPECT_EQ(renderer->width(), 321);
}

TEST(Renderer, ClearErrors) {
  SPIDAR_REQUIRE_GL();
  auto bad = Renderer::create(*gl_context(), 0, 10);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("size"), std::string::npos);
  auto renderer = Renderer::create(*gl_context(), 32, 32).value();
  RenderParams params;
  params.depth_range = {0.5, 0.1};
  auto s = renderer->render(SceneSnapshot{}, vision::default_rig_camera(), params);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("near < far"), std::string::npos);
  auto p = renderer->present(*gl_context(), cv::Mat(4, 4, CV_8UC3));
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("headless"), std::string::npos);
}

TEST(Context, WindowWithoutDisplaySaysSo) {
  const char* display = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if (display || wayland) GTEST_SKIP() << "a display is available here";
  auto w = Context::create_window();
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message.find("DISPLAY"), std::string::npos) << w.error().message;
}

}  // namespace
}  // namespace spidar::render
