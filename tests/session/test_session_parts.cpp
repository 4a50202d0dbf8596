// The session pieces shared by run, replay and the demo: the cube monitor's scramble and reset
// (the GUI's scene panel), the turn counter, the camera scaling.
#include <gtest/gtest.h>

#include <numbers>

#include "spidar/session/interactive_hands.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/session/scripted_task.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::session {
namespace {

TEST(CubeMonitor, ASceneWithoutACubeIsNotReportedSolved) {
  physics::WorldParams wp;
  auto world = physics::World::Load("scenes/blocks.xml", wp).value();
  std::optional<physics::RubiksCube> none;
  CubeMonitor monitor(&none, Pose{});
  monitor.before_step(*world);
  ASSERT_TRUE(monitor.status().read());
  EXPECT_FALSE(monitor.status().read()->solved);
  EXPECT_EQ(monitor.status().read()->turns, 0);
}

TEST(CubeMonitor, ScrambleAndResetRunInThePhysicsStepAndAreNotCountedAsTurns) {
  physics::WorldParams wp;
  auto world = physics::World::Load("scenes/rubiks_cube.xml", wp).value();
  auto cube_r = physics::RubiksCube::Attach(*world);
  ASSERT_TRUE(cube_r);
  std::optional<physics::RubiksCube> cube = std::move(cube_r).value();
  CubeMonitor monitor(&cube, cube->core_pose());
  monitor.before_step(*world);
  ASSERT_TRUE(monitor.status().read());
  EXPECT_TRUE(monitor.status().read()->solved);

  monitor.request_scramble(7);
  EXPECT_TRUE(cube->is_solved());  // nothing happens outside the physics step
  monitor.before_step(*world);
  auto s = monitor.status().read();
  ASSERT_TRUE(s);
  EXPECT_FALSE(s->solved);
  EXPECT_EQ(s->turns, 0);
  const std::string scrambled = cube->facelets();

  monitor.request_reset();
  monitor.before_step(*world);
  s = monitor.status().read();
  EXPECT_TRUE(s->solved);
  EXPECT_TRUE(cube->is_solved());
  EXPECT_NE(cube->facelets(), scrambled);
  EXPECT_EQ(s->turns, 0);
  EXPECT_NEAR(s->lift, 0.0, 1e-9);
  const auto p = monitor.pose().read();
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->p_W[2], cube->core_pose().p.z(), 1e-12);
  // The layer locks follow the reset (they were set for the scrambled places): stepping on, the
  // cube stays solved and every face at its click.
  std::vector<Vec3> parked(8, Vec3(0, 0.3, 0.3)), v(8, Vec3::Zero());
  for (int k = 0; k < 300; ++k) world->step(parked, v);
  EXPECT_TRUE(cube->is_solved());
  for (char f : std::string("UDFBRL")) EXPECT_LT(std::abs(cube->face_angle(f)), 0.02) << f;
}

TEST(TurnCounter, CountsSettledQuarterTurnsOfTheUser) {
  physics::WorldParams wp;
  auto world = physics::World::Load("scenes/rubiks_cube.xml", wp).value();
  auto cube = physics::RubiksCube::Attach(*world).value();
  TurnCounter turns;
  turns.update(cube);
  EXPECT_EQ(turns.turns(), 0);
  ASSERT_TRUE(cube.turn('U', 1));
  turns.update(cube);
  EXPECT_EQ(turns.turns(), 1);
  ASSERT_TRUE(cube.turn('R', 2));
  turns.rebase(cube);  // e.g. a scramble: not the user's
  turns.update(cube);
  EXPECT_EQ(turns.turns(), 1);
  // Per face: the scripted user's layer (U) apart from a layer dragged along (R, a half turn).
  ASSERT_TRUE(cube.turn('R', 2));
  turns.update(cube);
  EXPECT_EQ(turns.turns(), 3);
  EXPECT_EQ(turns.turns_of('U'), 1);
  EXPECT_EQ(turns.turns_of('R'), 2);
  EXPECT_EQ(turns.turns_of('F'), 0);
  EXPECT_EQ(turns.turns_of('x'), 0);
}

TEST(ScaledCamera, KeepsTheFieldOfViewAndPixelCentres) {
  vision::Intrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 554.256;
  k.cx = 319.5;
  k.cy = 239.5;
  const vision::Camera c(k, Pose());
  const vision::Camera h = scaled_camera(c, 1280, 960);
  EXPECT_DOUBLE_EQ(h.intrinsics().fx, 2 * k.fx);
  EXPECT_DOUBLE_EQ(h.intrinsics().cx, 639.5);
  EXPECT_EQ(h.intrinsics().width, 1280);
}

TEST(InteractiveHands, ControlsMoveAndCloseTheHandsAndTheirCapsAreTheDeviceGoals) {
  const auto models = hand_models("configs/hands.yaml", "user", true);
  sim::RubiksTask task({});
  std::array<hand::HandParams, 2> open, closed;
  for (int h = 0; h < 2; ++h) {
    const auto side = h == 0 ? hand::Side::kLeft : hand::Side::kRight;
    open[h] = task.nominal(0.0, side);
    closed[h] = task.nominal(2.0, side);
  }
  InteractiveHands hands(models, open, closed);
  std::array<Vec3, 8> g0, g1;
  hands.goals(0, g0);
  for (int h = 0; h < 2; ++h) {  // at rest: the open posture's caps
    const auto pts = hand::forward_kinematics(models[h], open[h]);
    for (int f = 0; f < 4; ++f) EXPECT_NEAR((g0[4 * h + f] - pts.p_W_fingertip[f]).norm(), 0.0, 1e-12);
  }
  HandControls c;
  c[1].offset_W = {0.02, -0.01, 0.03};
  hands.set(c);
  hands.goals(0, g1);
  for (int f = 0; f < 4; ++f) {
    EXPECT_NEAR((g1[f] - g0[f]).norm(), 0.0, 1e-12);                                 // left stays
    EXPECT_NEAR((g1[4 + f] - g0[4 + f] - Vec3(0.02, -0.01, 0.03)).norm(), 0.0, 1e-12);  // right moves
  }
  // Closing brings the thumb and index caps together; yaw turns the hand about the vertical.
  c = {};
  c[0].closeness = 1.0;
  hands.set(c);
  hands.goals(0, g1);
  EXPECT_LT((g1[0] - g1[1]).norm(), (g0[0] - g0[1]).norm());
  c = {};
  c[0].yaw = 0.5;
  c[0].closeness = 7.0;  // clamped to 1
  hands.set(c);
  EXPECT_EQ(hands.controls()[0].closeness, 1.0);
  const auto q = hands.pose(hands.controls());
  EXPECT_NEAR((q[0].p_W_wrist() - open[0].p_W_wrist()).norm(), 0.0, 1e-12);
  EXPECT_GT((q[0].r_W_hand() - open[0].r_W_hand()).norm(), 0.1);
}

}  // namespace
}  // namespace spidar::session

namespace spidar::session {
namespace {

Shape object(Shape::Type type, const Vec3& size, const Quat& q = Quat::Identity(), const Vec3& p = Vec3(0.02, 0, 0)) {
  Shape s;
  s.type = type;
  s.size = size;
  s.X_WS = Pose{q, p};
  s.body = 1;
  return s;
}

// The object the scripted user pinches (thumb to fingers along world y): its extent across the
// pinch, whatever its kind and turn, against the brute-force extent of its surface points.
TEST(ReachTarget, MeasuresTheObjectAcrossThePinchAndRefusesWhatItCannotHold) {
  const Quat turned(Eigen::AngleAxisd(0.6, Vec3(0.3, -0.5, 0.8).normalized()));
  // Brute force: the half extent along y of points sampled on the shape.
  auto sampled = [](const Shape& s) {
    const Mat3 R = s.X_WS.R.toRotationMatrix();
    double hi = 0;
    auto see = [&](const Vec3& p) { hi = std::max(hi, (R * p).y()); };
    constexpr int n = 60;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const double a = -1 + 2.0 * i / n, b = -1 + 2.0 * j / n;
        const double phi = 2 * std::numbers::pi * i / n, theta = std::numbers::pi * j / n;
        const Vec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        if (s.type == Shape::Type::kBox)
          for (int k = 0; k <= n; ++k) see(Vec3(a, b, -1 + 2.0 * k / n).cwiseProduct(s.size));
        else if (s.type == Shape::Type::kSphere) see(s.size.x() * dir);
        else if (s.type == Shape::Type::kCapsule)
          for (int k = 0; k <= n; ++k) see(Vec3(0, 0, s.size.y() * (-1 + 2.0 * k / n)) + s.size.x() * dir);
        else
          see(Vec3(s.size.x() * std::cos(phi), s.size.x() * std::sin(phi), s.size.y() * b));
      }
    return hi;
  };
  for (const Shape& s : {object(Shape::Type::kBox, Vec3(0.01, 0.03, 0.02), turned),
                         object(Shape::Type::kSphere, Vec3(0.025, 0, 0), turned),
                         object(Shape::Type::kCapsule, Vec3(0.01, 0.03, 0), turned),
                         object(Shape::Type::kCylinder, Vec3(0.015, 0.02, 0), turned)})
    EXPECT_NEAR(pinch_half_extent(s), sampled(s), 2e-4) << static_cast<int>(s.type);

  SceneSnapshot scene;
  sim::RubiksTaskParams tp;
  // Nothing to reach for: the world's own geoms only.
  Shape table = object(Shape::Type::kBox, Vec3(0.3, 0.3, 0.01));
  table.body = 0;
  scene.shapes = {table};
  auto st = reach_target(scene, &tp);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("no object for the scripted user to reach for"), std::string::npos);
  // The nearest of two objects, with its extent as the half size.
  scene.shapes.push_back(object(Shape::Type::kBox, Vec3(0.02, 0.03, 0.02), Quat::Identity(), Vec3(0.2, 0, 0)));
  scene.shapes.push_back(object(Shape::Type::kSphere, Vec3(0.025, 0, 0), Quat::Identity(), Vec3(0.05, 0.01, 0)));
  ASSERT_TRUE(reach_target(scene, &tp));
  EXPECT_EQ(tp.p_W_cube, Vec3(0.05, 0.01, 0));
  EXPECT_DOUBLE_EQ(tp.half, 0.025);
  // Too large for one hand's pinch (180 mm across): refused, not held from inside.
  scene.shapes = {table, object(Shape::Type::kBox, Vec3(0.09, 0.09, 0.09))};
  st = reach_target(scene, &tp);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("is 180 mm across the scripted user's pinch"), std::string::npos)
      << st.error().message;
  EXPECT_NE(st.error().message.find("20 to 100 mm"), std::string::npos) << st.error().message;
  // A box long in x but narrow across the pinch is held.
  scene.shapes = {table, object(Shape::Type::kBox, Vec3(0.09, 0.03, 0.03))};
  EXPECT_TRUE(reach_target(scene, &tp));
}

}  // namespace
}  // namespace spidar::session
