#pragma once
/// The virtual world of a session: the MJCF scene, its Rubik's cube if it has one, the scripted
/// user's task in it (fitted to the user's hands) and the cube monitor the physics thread feeds.
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "spidar/core/result.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/scripted_task.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::session {

struct Scene {
  /// Loads `path` (MJCF) and fits the scripted task to the user's hands `user` (left, right);
  /// `user_options`: how the scripted user plays (make_scripted_task).
  /// The error says what in the scene is wrong (callers prefix the option or config key).
  static Result<std::unique_ptr<Scene>> load(const std::string& path,
                                             const std::array<hand::HandModel, 2>& user,
                                             const ScriptedUserOptions& user_options = {});
  Scene() = default;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// The start posture's wrist rotation vectors of both hands (left, right), world frame [rad]:
  /// where the fits start.
  std::array<Vec3, 2> initial_r_W_hand() const;

  physics::WorldParams params;
  std::unique_ptr<physics::World> world;
  std::optional<physics::RubiksCube> cube;  ///< empty: a scene without a Rubik's cube
  std::shared_ptr<sim::RubiksTask> task;    ///< the scripted user's task
  std::unique_ptr<CubeMonitor> monitor;     ///< fed by the physics thread
};

}  // namespace spidar::session
