// The scripted Rubik's task on the real physics, in lockstep (no threads, no device): the user's
// fingertips follow the script's goals through the fingertip impedance and feel the coupling
// forces, one physics step at a time. Deterministic, so the script and the cube's layer locks
// are checked without the timing of a busy machine.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lockstep_task.hpp"
#include "temp_path.hpp"
#include "spidar/core/units.hpp"
#include "spidar/hand/coupling.hpp"
#include "spidar/hand/hand_config.hpp"

namespace spidar::sim {
namespace {

struct TaskRun {
  double lift_max_m = 0;
  int quarter_turns_u = 0;  ///< U's final angle in quarter turns
  int unlocks = 0;
  std::array<double, 6> other_faces_max_rad{};  ///< D F B R L: largest |angle| seen
  bool solved = true;
};

/// `fit`: the user's hands the script is fitted to (RubiksTask::fit_to_hands), or nullptr.
TaskRun run_task(const std::array<hand::HandModel, 2>* fit = nullptr, const std::string& scene = {}) {
  TaskRun r;
  double z0 = 0;
  bool first = true;
  run_lockstep(
      [&](RubiksTask& task) {
        if (fit) task.fit_to_hands(*fit);
      },
      [&](double, std::span<const Vec3>, const physics::RubiksCube& cube) {
        const Pose X = cube.core_pose();
        if (first) z0 = X.p.z(), first = false;  // the start (the first step barely moves it)
        r.lift_max_m = std::max(r.lift_max_m, X.p.z() - z0);
        for (int f = 1; f < 6; ++f)
          r.other_faces_max_rad[f] = std::max(r.other_faces_max_rad[f], std::abs(cube.face_angle("UDFBRL"[f])));
        // At the end: U's angle, the unlocks, solved or not (kept from the last step).
        r.quarter_turns_u = u_quarter_turns(cube);
        r.unlocks = cube.layer_unlocks();
        r.solved = cube.is_solved();
      },
      false, scene);
  return r;
}

TEST(RubiksTask, LockstepPhysicsLiftsAndTurnsTheTopLayerTwice) {
  const TaskRun r = run_task();
  std::printf("lift %.1f mm, U %d quarter turns, %d unlocks, other faces within %.2f deg\n",
              r.lift_max_m * 1e3, r.quarter_turns_u, r.unlocks,
              *std::max_element(r.other_faces_max_rad.begin(), r.other_faces_max_rad.end()) * 180 / units::kPi);
  EXPECT_GT(r.lift_max_m, 0.010);  // the left hand lifts the cube (script: 20 mm)
  EXPECT_EQ(r.quarter_turns_u, 2);  // two turns of the top layer, each clicked into place
  EXPECT_FALSE(r.solved);
  // The grasps twist no other layer out of its click.
  for (int f = 1; f < 6; ++f) EXPECT_LT(r.other_faces_max_rad[f], units::deg_to_rad(3)) << "UDFBRL"[f];
}

// The script fitted to users' own hands (their fingers reach the caps) still turns twice: the
// default user, and users ±10 % in length and width with either coupling. (In the real-time demo
// the short, wide user with the linear coupling (`--user-hand` with length 0.171,
// width 0.0935, fingertip_offset [0, -0.009, 0.001]) has failed its second turn in every run so
// far, 2026-11-25: that is the rig's timing and strings, not the script; lockstep it turns.)
struct UserShape {
  double length_scale, width_scale;
  hand::Coupling coupling;
};

class FittedTaskPhysics : public ::testing::TestWithParam<UserShape> {};

TEST_P(FittedTaskPhysics, LiftsAndTurnsTheTopLayerTwice) {
  hand::HandProfile profile;
  profile.dimensions.length = 0.19 * GetParam().length_scale;
  profile.dimensions.width = 0.085 * GetParam().width_scale;
  profile.dimensions.fingertip_offset = Vec3(0.0, -0.009, 0.001);  // the `user` profile's caps
  profile.coupling = GetParam().coupling;
  const std::array<hand::HandModel, 2> hands{profile.model(hand::Side::kLeft),
                                             profile.model(hand::Side::kRight)};
  const TaskRun r = run_task(&hands);
  std::printf("length x%.2f width x%.2f %s: lift %.1f mm, U %d quarter turns\n", GetParam().length_scale,
              GetParam().width_scale, GetParam().coupling == hand::Coupling::kLinear ? "linear" : "quadratic",
              r.lift_max_m * 1e3, r.quarter_turns_u);
  EXPECT_GT(r.lift_max_m, 0.010);
  EXPECT_EQ(r.quarter_turns_u, 2);
}

INSTANTIATE_TEST_SUITE_P(Users, FittedTaskPhysics,
                         ::testing::Values(UserShape{1.04, 0.97, hand::Coupling::kPaperQuadratic},
                                           UserShape{0.9, 1.1, hand::Coupling::kLinear},
                                           UserShape{1.1, 0.9, hand::Coupling::kLinear},
                                           UserShape{0.9, 0.9, hand::Coupling::kPaperQuadratic},
                                           UserShape{1.1, 1.1, hand::Coupling::kPaperQuadratic}));

// The cube elsewhere on the table and turned about the vertical: the user grasps it where it lies
// (RubiksTask::track), so the task is the same. A scene of its own per placement, written from
// scenes/rubiks_cube.xml with the cube's body moved.
struct CubePlacement {
  double x_m, y_m, yaw_rad;
};

std::string placed_cube_scene(const CubePlacement& c) {
  std::ifstream in(spidar::test::source("scenes/rubiks_cube.xml"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string xml = ss.str();
  const std::string body = "<body name=\"cube\" pos=\"0 0 -0.00130\">";
  const auto at = xml.find(body);
  EXPECT_NE(at, std::string::npos);
  char placed[160];
  std::snprintf(placed, sizeof placed, "<body name=\"cube\" pos=\"%.4f %.4f -0.00130\" euler=\"0 0 %.4f\">", c.x_m,
                c.y_m, c.yaw_rad);
  xml.replace(at, body.size(), placed);
  // In this process's own folder: ctest runs the placements in parallel processes, and one
  // writing a file while another reads it would race.
  char name[96];
  std::snprintf(name, sizeof name, "rubiks_placed_%+.3f_%+.3f_%+.3f.xml", c.x_m, c.y_m, c.yaw_rad);
  static const std::string dir = spidar::test::temp_dir("spidar_placed_cube");
  const std::string path = (std::filesystem::path(dir) / name).string();
  std::ofstream(path) << xml;
  return path;
}

/// Hands of the demo's default user's sizes and caps (configs/hands.yaml, profile `user`), with the
/// default joint ranges (that profile's abduction is ±18°).
std::array<hand::HandModel, 2> user_sizes_hands() {
  hand::HandProfile profile;
  profile.dimensions.length = 0.1976;
  profile.dimensions.width = 0.0825;
  profile.dimensions.fingertip_offset = Vec3(0.0, -0.009, 0.001);
  return {profile.model(hand::Side::kLeft), profile.model(hand::Side::kRight)};
}

class PlacedCube : public ::testing::TestWithParam<CubePlacement> {};

// Lockstep (the fingertips feel the coupling forces exactly, no strings): at every placement the
// script, fitted to the default user's hands, lifts the cube and turns the top layer twice.
TEST_P(PlacedCube, LiftsAndTurnsTheTopLayerTwice) {
  const std::array<hand::HandModel, 2> hands = user_sizes_hands();
  const TaskRun r = run_task(&hands, placed_cube_scene(GetParam()));
  std::printf("cube at %.3f, %.3f m, turned %.2f rad: lift %.1f mm, U %d quarter turns\n", GetParam().x_m,
              GetParam().y_m, GetParam().yaw_rad, r.lift_max_m * 1e3, r.quarter_turns_u);
  EXPECT_GT(r.lift_max_m, 0.010);
  EXPECT_EQ(r.quarter_turns_u, 2);
}

// The same task through the simulated device (run_lockstep_device): the user feels only what the
// strings display. At the default placement it turns twice, as the demo does. Turned about the
// vertical it makes one turn at some angles, as the demo does (this profile: 0.35 rad; configs/
// hands.yaml's `user`, abduction within ±18°: 0.2, 0.35, 0.45 rad; both: none of −0.45 … −0.05):
// in turn 2 the cube hangs tilted about 20° in the left hand (also without the device), the right
// index and ring display under 2 N of the 8–14 N the coupling asks for, and at those angles the
// cube turns as a whole instead of its top layer. PlacedCubeThroughTheDevice checks the grasp that
// holds there (RubiksTaskParams::ring_on_side).
TEST(RubiksTask, LockstepPhysicsThroughTheDeviceTurnsTwice) {
  const std::array<hand::HandModel, 2> hands = user_sizes_hands();
  int quarter_turns = 0;
  run_lockstep_device([&](RubiksTask& task) { task.fit_to_hands(hands); },
                      [&](double, std::span<const Vec3>, const physics::RubiksCube& cube) {
                        quarter_turns = u_quarter_turns(cube);
                      });
  EXPECT_EQ(quarter_turns, 2);
}

// The same placements through the simulated device (run_lockstep_device), where each finger feels
// only what its three pulling strings can display: the grasp must put each finger on a face its
// unit can push it back from (RubiksTaskParams::ring_on_side: the left ring on the left face, the
// session's default). With the left ring on the back face (RubiksTaskParams' default), 3 of 8
// such placements turned twice (docs/measurements.md); these four turn once that way.
class PlacedCubeThroughTheDevice : public ::testing::TestWithParam<CubePlacement> {};

/// U's quarter turns at the end of the session's scripted task (the ring on the left face, the
/// script fitted 0.1 rad inside the holding hand's joint ranges: session::ScriptedUserOptions'
/// defaults) for the
/// user of `hands_file` (its profile `user`, else its first) with the cube at `c`, through the
/// simulated device.
int session_task_through_the_device(const std::string& hands_file, const CubePlacement& c) {
  const std::array<hand::HandModel, 2> hands = profile_hands(hands_file);
  int quarter_turns = 0;
  run_lockstep_device([&](RubiksTask& task) { task.fit_to_hands(hands, 0.01, std::array<double, 2>{0.1, 0.0}); },
                      [&](double, std::span<const Vec3>, const physics::RubiksCube& cube) {
                        quarter_turns = u_quarter_turns(cube);
                      },
                      placed_cube_scene(c), /*ring_on_side=*/true);
  std::printf("%s, cube at %.3f, %.3f m, turned %.2f rad, through the device: U %d quarter turns\n",
              hands_file.c_str(), c.x_m, c.y_m, c.yaw_rad, quarter_turns);
  return quarter_turns;
}

TEST_P(PlacedCubeThroughTheDevice, LiftsAndTurnsTheTopLayerTwice) {
  EXPECT_EQ(session_task_through_the_device("configs/hands.yaml", GetParam()), 2);  // the demo's default user
}

// The same for the users ±10 % whose fingers are longest, each at a placement that failed with the
// back-face grasp. (Session 46, lockstep: the five users of configs/ at six placements each, the
// shipped one included, turned twice in 30 of 30 runs.)
TEST(PlacedCubeLongHands, TurnTheLayerTwiceThroughTheDevice) {
  EXPECT_EQ(session_task_through_the_device("configs/users/large.yaml", {0.04, 0.03, 0.45}), 2);
  EXPECT_EQ(session_task_through_the_device("configs/users/long-narrow.yaml", {-0.05, -0.02, -0.3}), 2);
}

INSTANTIATE_TEST_SUITE_P(Placements, PlacedCubeThroughTheDevice,
                         ::testing::Values(CubePlacement{0.0, 0.0, 0.45}, CubePlacement{0.04, 0.03, 0.45},
                                           CubePlacement{-0.05, -0.02, -0.3}, CubePlacement{0.0, 0.0, 0.2}));

INSTANTIATE_TEST_SUITE_P(Placements, PlacedCube,
                         ::testing::Values(CubePlacement{0.04, 0.03, 0.45}, CubePlacement{-0.05, -0.02, -0.3},
                                           CubePlacement{0.0, 0.0, 0.45}, CubePlacement{0.04, 0.03, 0.0}));

}  // namespace
}  // namespace spidar::sim
