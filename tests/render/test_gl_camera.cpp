// The camera → GL conversion against vision::Camera, without a GL context.
#include <gtest/gtest.h>

#include "render_test_cameras.hpp"

#include <random>

#include "spidar/render/gl_camera.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/renderer.hpp"

namespace spidar::render {
namespace {

using testing::odd_camera;

TEST(GlCamera, ClipSpaceLandsOnCameraProjectAndDepth) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const DepthRange range{0.05, 3.0};
  for (const vision::Camera& cam : {vision::default_rig_camera(), odd_camera()}) {
    for (int i = 0; i < 200; ++i) {
      const Vec3 p_W(u(rng), u(rng), u(rng));
      const Vec3 gl = gl_pixel_and_depth(cam, range, p_W);
      const Vec2 uv = cam.project(p_W);
      EXPECT_NEAR(gl.x(), uv.x(), 1e-9);
      EXPECT_NEAR(gl.y(), uv.y(), 1e-9);
      EXPECT_NEAR(gl.z(), cam.depth(p_W), 1e-12);
    }
  }
}

TEST(GlCamera, PixelCentresAndNearFarPlanes) {
  const vision::Camera cam = odd_camera();
  const DepthRange range{0.05, 3.0};
  const Mat4 P = gl_projection(cam.intrinsics(), range);
  // The top-left pixel's centre (0, 0) sits half a pixel inside NDC's corner (−1, −1).
  const Vec3 p_C = cam.unproject_camera(Vec2(0, 0), 1.0);
  const Vec4 clip = P * p_C.homogeneous();
  EXPECT_NEAR(clip.x() / clip.w(), -1.0 + 1.0 / cam.width(), 1e-12);
  EXPECT_NEAR(clip.y() / clip.w(), -1.0 + 1.0 / cam.height(), 1e-12);
  for (double z : {range.near_m, range.far_m}) {
    const Vec4 c = P * Vec4(0, 0, z, 1);
    EXPECT_NEAR(c.z() / c.w(), z == range.near_m ? -1.0 : 1.0, 1e-12);
  }
  EXPECT_FALSE(validate(DepthRange{0.0, 1.0}).ok());
  EXPECT_FALSE(validate(DepthRange{1.0, 0.5}).ok());
  EXPECT_NE(validate(DepthRange{-1, 1}).error().message.find("near"), std::string::npos);
}

TEST(GlCamera, HandIdRoundTrip) {
  for (int h = 0; h < 2; ++h)
    for (int f = -1; f <= 6; ++f) {
      const HandId id = decode_hand_id(encode_hand_id(h, f));
      EXPECT_EQ(id.hand, h);
      EXPECT_EQ(id.finger, f);
      EXPECT_NE(encode_hand_id(h, f), 0);
    }
  EXPECT_EQ(decode_hand_id(0).hand, -1);
}

TEST(GlCamera, CapsuleShapeSpansItsSegment) {
  const Vec3 a(0.1, 0.2, 0.3), b(0.12, 0.17, 0.33);
  const Shape s = capsule_shape(a, b, 0.008);
  EXPECT_NEAR((s.X_WS * Vec3(0, 0, -s.size.y()) - a).norm(), 0, 1e-12);
  EXPECT_NEAR((s.X_WS * Vec3(0, 0, s.size.y()) - b).norm(), 0, 1e-12);
  EXPECT_EQ(s.size.x(), 0.008);
}

}  // namespace
}  // namespace spidar::render
