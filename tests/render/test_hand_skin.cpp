// The model hand's skin (render/hand_skin.hpp): its tessellation and its parameter checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <iostream>
#include <string>
#include <utility>
#include <vector>
#include <limits>
#include <opencv2/core.hpp>

#include "gl_test_support.hpp"
#include "spidar/hand/forearm.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/vision/camera.hpp"
#include "synthetic_hands.hpp"

namespace spidar {
namespace {

/// Triangles of both hands' skins and their silhouette (hand pixels, forearm included) at `q`.
struct SkinPicture {
  std::size_t triangles = 0;
  cv::Mat mask;
};

SkinPicture draw_skin(const render::HandSkinParams& p, const std::array<hand::HandParams, 2>& q) {
  const auto models = render::test::truth_models();
  auto meshes = std::make_shared<std::vector<MeshData>>();
  std::array<render::HandSkin, 2> skins;
  for (int h = 0; h < 2; ++h) skins[h] = render::build_hand_skin(models[h], p, meshes.get());
  SkinPicture out;
  for (const MeshData& m : *meshes) out.triangles += m.faces.size() / 3;
  SceneSnapshot scene;
  scene.meshes = meshes;
  for (int h = 0; h < 2; ++h) render::pose_hand_skin(models[h], skins[h], q[h], p, &scene);
  const vision::Camera cam = vision::default_rig_camera();
  auto renderer = render::Renderer::create(*render::test::gl_context()).value();
  EXPECT_TRUE(renderer->render(scene, cam).ok());
  render::RenderTargets t;
  EXPECT_TRUE(renderer->read(&t, render::kHandId).ok());
  out.mask = t.hand_id != 0;
  return out;
}

double skin_mask_iou(const cv::Mat& a, const cv::Mat& b) {
  const double inter = cv::countNonZero(a & b), uni = cv::countNonZero(a | b);
  return uni > 0 ? inter / uni : 1.0;
}

TEST(HandSkin, CoarseTessellationKeepsTheSilhouetteWithHalfTheTriangles) {
  SPIDAR_REQUIRE_GL();
  render::HandSkinParams fine;  // the tessellation before the pipeline's budget cut
  fine.bone_slices = 16;
  fine.bone_rings = 6;
  fine.palm_slices = 24;
  fine.palm_stacks = 16;
  const render::HandSkinParams coarse;  // the defaults
  // Reaching (fingers spread) and two other hand positions (a different view of the fingers).
  for (double dx : {0.0, 0.03, -0.04}) {
    const auto q = render::test::reaching_hands(dx);
    const SkinPicture a = draw_skin(fine, q), b = draw_skin(coarse, q);
    ASSERT_GT(cv::countNonZero(a.mask), 5000) << "the hands must be in view (dx " << dx << ")";
    EXPECT_LT(static_cast<double>(b.triangles), 0.5 * static_cast<double>(a.triangles))
        << b.triangles << " vs " << a.triangles;
    const double score = skin_mask_iou(a.mask, b.mask);
    std::cout << "dx " << dx << ": " << b.triangles << " triangles vs " << a.triangles
              << ", silhouette IoU " << score << "\n";
    EXPECT_GT(score, 0.98) << "dx " << dx;
  }
}

TEST(HandSkin, ValidateNamesTheFieldOutOfRange) {
  EXPECT_TRUE(render::validate(render::HandSkinParams{}).ok());
  render::HandSkinParams p;
  p.bone_slices = 2;
  auto s = render::validate(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("bone_slices"), std::string::npos) << s.error().message;
  EXPECT_NE(s.error().message.find("6..64"), std::string::npos) << s.error().message;
  p = {};
  p.palm_stacks = 1000;
  s = render::validate(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("palm_stacks"), std::string::npos) << s.error().message;
  p = {};
  p.taper = std::numeric_limits<double>::quiet_NaN();
  s = render::validate(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("taper"), std::string::npos) << s.error().message;
  // Each value of `field` is refused with `message`.
  auto refused = [](double render::HandSkinParams::*field, std::initializer_list<double> values,
                    const std::string& message) {
    for (double bad : values) {
      render::HandSkinParams q;
      q.*field = bad;
      const auto st = render::validate(q);
      ASSERT_FALSE(st.ok()) << bad;
      EXPECT_NE(st.error().message.find(message), std::string::npos) << st.error().message;
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  refused(&render::HandSkinParams::palm_wrist_breadth, {0.4, 1.5, nan}, "palm_wrist_breadth must be in [0.5, 1]");
  refused(&render::HandSkinParams::forearm_cap_depth, {0.0, 1.5, nan}, "forearm_cap_depth must be in (0, 1]");
  refused(&render::HandSkinParams::forearm_breadth, {0.3, 1.2, nan}, "forearm_breadth must be in [0.4, 1]");
  refused(&render::HandSkinParams::forearm_depth, {0.3, 1.2, nan}, "forearm_depth must be in [0.4, 1]");
}

/// Extent of a mesh's vertices along axis `k` of its frame: {min, max} [m].
std::pair<double, double> extent(const MeshData& m, int k) {
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = static_cast<std::size_t>(k); i < m.vertices.size(); i += 3) {
    lo = std::min(lo, static_cast<double>(m.vertices[i]));
    hi = std::max(hi, static_cast<double>(m.vertices[i]));
  }
  return {lo, hi};
}

// The carpus is hand: the forearm's end reaches a quarter of its radius past the wrist (it reached
// its whole radius, 2.5–3 cm into the palm), and the palm's skin reaches back to the wrist from
// the skeleton's palm box, which starts at the carpus.
TEST(HandSkin, TheForearmEndsAtTheWristAndThePalmReachesIt) {
  for (const hand::Side side : {hand::Side::kLeft, hand::Side::kRight}) {
    const hand::HandModel model = hand::default_hand_model(side);
    const hand::PalmBox& box = model.shape.palm;
    const double carpus = box.p_H_centre.y() - box.half_extents.y();  // the palm box's start
    ASSERT_GT(carpus, 0.005) << "the skeleton's palm box starts at the carpus, not at the wrist";
    std::vector<double> ends;
    for (const bool reaches : {true, false}) {
      render::HandSkinParams p;
      p.palm_reaches_wrist = reaches;
      std::vector<MeshData> meshes;
      const render::HandSkin skin = render::build_hand_skin(model, p, &meshes);
      ASSERT_GE(skin.forearm_mesh, 0);
      // The forearm's frame: z from the wrist toward the elbow.
      const auto arm_z = extent(meshes[static_cast<std::size_t>(skin.forearm_mesh)], 2);
      EXPECT_NEAR(arm_z.first, -0.25 * skin.wrist_half_breadth, 1e-6);
      // The palm mesh in the box frame (the axes of H, at the box's centre).
      const auto palm_y = extent(meshes[static_cast<std::size_t>(skin.palm_mesh)], 1);
      const double start_H = box.p_H_centre.y() + palm_y.first;
      const double end_H = box.p_H_centre.y() + palm_y.second;
      if (reaches) {
        EXPECT_NEAR(start_H, 0.0, 0.002) << "the palm's skin starts at the wrist";
      } else {
        EXPECT_NEAR(start_H, carpus, 0.002) << "the palm's skin starts at the carpus";
      }
      ends.push_back(end_H);
    }
    // Its breadth (x) at the wrist end is palm_wrist_breadth of the breadth at the knuckles.
    render::HandSkinParams p;
    std::vector<MeshData> meshes;
    const render::HandSkin skin = render::build_hand_skin(model, p, &meshes);
    const MeshData& palm = meshes[static_cast<std::size_t>(skin.palm_mesh)];
    const auto y = extent(palm, 1);
    auto breadth_near = [&](double y_at) {  // x extent of the vertices within 3 mm of y_at
      double lo = 1e300, hi = -1e300;
      for (std::size_t i = 0; i + 2 < palm.vertices.size(); i += 3)
        if (std::abs(palm.vertices[i + 1] - y_at) < 0.003)
          lo = std::min(lo, static_cast<double>(palm.vertices[i])), hi = std::max(hi, static_cast<double>(palm.vertices[i]));
      return hi - lo;
    };
    const double wrist = breadth_near(y.first + 0.004), knuckles = breadth_near(y.second - 0.004);
    EXPECT_NEAR(wrist / knuckles, p.palm_wrist_breadth, 0.05) << wrist << " vs " << knuckles;
    // Its distal end stays at the MCP line either way (within 0.2 mm: the tessellation's outermost
    // vertices sit a little inside the longer box's end).
    EXPECT_NEAR(ends[0], ends[1], 2e-4);
  }
}

// A wrist is broader than it is deep: the forearm's section is an ellipse forearm_breadth of the
// palm's half breadth across x_H and forearm_depth of that along z_H (a round forearm as broad as
// the wrist stood out of the palm above and below), and the bracelet is a band just proud of it.
// Posed, the broad axis lies along the hand's x for any rotation of the hand.
TEST(HandSkin, TheForearmIsBroaderThanDeepAcrossThePalm) {
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  render::HandSkinParams p;
  std::vector<MeshData> meshes;
  const render::HandSkin skin = render::build_hand_skin(model, p, &meshes);
  ASSERT_GE(skin.forearm_mesh, 0);
  ASSERT_GE(skin.bracelet_mesh, 0);
  const double half_breadth = p.forearm_breadth * model.shape.palm.half_extents.x();
  EXPECT_NEAR(skin.wrist_half_breadth, half_breadth, 1e-12);
  EXPECT_NEAR(skin.wrist_half_depth, p.forearm_depth * half_breadth, 1e-12);
  // Near the wrist (z within 1 mm of it) the vertices span the ellipse's axes, and everywhere the
  // section is forearm_depth as deep as it is broad.
  const MeshData& arm = meshes[static_cast<std::size_t>(skin.forearm_mesh)];
  double x_wrist = 0, x_max = 0, y_max = 0;
  for (std::size_t i = 0; i + 2 < arm.vertices.size(); i += 3) {
    const double x = std::abs(static_cast<double>(arm.vertices[i]));
    if (std::abs(arm.vertices[i + 2]) < 1e-3) x_wrist = std::max(x_wrist, x);
    x_max = std::max(x_max, x);
    y_max = std::max(y_max, std::abs(static_cast<double>(arm.vertices[i + 1])));
  }
  EXPECT_NEAR(x_wrist, half_breadth, 5e-4);
  EXPECT_NEAR(y_max / x_max, p.forearm_depth, 1e-5);
  // The band: 2 mm proud of the forearm at its centre, bracelet_width_m long (ends 5 % domed).
  const MeshData& band = meshes[static_cast<std::size_t>(skin.bracelet_mesh)];
  const auto band_x = extent(band, 0), band_y = extent(band, 1), band_z = extent(band, 2);
  const double grow = 1 + 0.15 * p.bracelet_offset_m / p.forearm_length_m;
  EXPECT_NEAR(band_x.second, half_breadth * grow + 0.002, 1e-4);
  EXPECT_NEAR(band_y.second, p.forearm_depth * half_breadth * grow + 0.002, 1e-4);
  EXPECT_NEAR(band_z.second - band_z.first, p.bracelet_width_m + 0.1 * (half_breadth * grow + 0.002), 1e-4);

  // Posed with the hand turned about an arbitrary axis: the forearm's x is x_H, its z −y_H.
  hand::HandParams q;
  q.set_wrist(Vec3(0.01, 0.02, 0.3), Vec3(0.3, -1.1, 0.7));
  SceneSnapshot scene;
  render::pose_hand_skin(model, skin, q, p, &scene);
  const Mat3 R_WH = hand::rotation_from_vector(q.r_W_hand());
  int checked = 0;
  for (const Shape& s : scene.shapes) {
    if (s.finger != render::kForearmPart && s.finger != render::kBraceletPart) continue;
    const Mat3 R = s.X_WS.R.toRotationMatrix();
    EXPECT_LT((R.col(0) - R_WH.col(0)).norm(), 1e-9);
    EXPECT_LT((R.col(2) + R_WH.col(1)).norm(), 1e-9);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
    ++checked;
  }
  EXPECT_EQ(checked, 2);

  // Bent at the wrist toward an elbow: the forearm and the band point along it, pronated with the
  // hand (the shortest arc from −y_H), and start at the wrist.
  const Vec3 d = Eigen::AngleAxisd(0.7, R_WH.col(2)) * Vec3(-R_WH.col(1));
  SceneSnapshot bent;
  render::pose_hand_skin(model, skin, q, p, &bent, &d);
  const Mat3 B = hand::wrist_bend(R_WH, d);
  checked = 0;
  for (const Shape& s : bent.shapes) {
    if (s.finger != render::kForearmPart && s.finger != render::kBraceletPart) continue;
    const Mat3 R = s.X_WS.R.toRotationMatrix();
    EXPECT_LT((R.col(2) - d).norm(), 1e-9);
    EXPECT_LT((R.col(0) - B * R_WH.col(0)).norm(), 1e-9);
    const double along = (s.X_WS.p - q.p_W_wrist()).dot(d);
    EXPECT_LT((s.X_WS.p - q.p_W_wrist() - along * d).norm(), 1e-9) << "on the forearm's axis";
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

}  // namespace
}  // namespace spidar
