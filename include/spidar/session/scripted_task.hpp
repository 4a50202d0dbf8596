#pragma once
/// The scripted user's task in a scene: the Rubik's cube's turns, or a reach for the object
/// nearest the frame centre when the scene has no cube.
#include <array>
#include <memory>
#include <optional>

#include "spidar/core/pose.hpp"
#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::session {

/// The scripted user's pinch (thumb on one side, fingers on the other, along world y) holds
/// objects this many metres across at least and at most (twice RubiksTaskParams::half).
inline constexpr double kMinPinchAcrossM = 0.02;
inline constexpr double kMaxPinchAcrossM = 0.10;

/// An object's half extent along world y, across the scripted user's pinch [m]: a box's or
/// mesh's (size as half sizes) turned by its pose, a sphere's radius, a capsule's or cylinder's
/// axis turned by its pose plus its radius. 0 for a plane.
double pinch_half_extent(const Shape& shape);

/// The object the scripted user reaches for in a scene without a cube: the shape of a body of its
/// own (not the world's, not a hand's proxy, not a plane) whose centre is nearest the frame
/// centre; nullptr when there is none. Points into `scene`.
const Shape* nearest_object(const SceneSnapshot& scene);

/// Where the scripted user reaches in a scene without a cube: the non-static object nearest the
/// frame centre (its centre, and pinch_half_extent as the half size). Fails, naming the object's
/// place and size, when the scene has no such object, or when it is too small or too large for the
/// pinch (kMinPinchAcrossM, kMaxPinchAcrossM).
Status reach_target(const SceneSnapshot& scene, sim::RubiksTaskParams* tp);

/// How the scripted user plays its task.
struct ScriptedUserOptions {
  double deadline_s = 0;        ///< > 0: the run time by which it must be done (retries must fit) [s]
  bool shaped_fingers = false;  ///< sim::RubiksTaskParams::shaped_fingers
  /// sim::RubiksTaskParams::ring_on_side: the holding hand's ring finger on the cube's left face,
  /// where its strings can push it back (the library's RubiksTaskParams keeps the back face).
  bool ring_on_side = true;
  /// The script is fitted to the user's holding (left) hand this far inside its finger joints'
  /// ranges [rad] (sim::RubiksTask::fit_to_hands' limit_margin_rad; the turning hand's is 0), so
  /// that its fingers can follow their caps where the displayed forces press them. With the ring
  /// on the side and 0, users 10 % longer miss their caps by 1.4–2.0 mm (the left index pressed
  /// past its passive abduction range); with 0.1, every user ±10 % within 0.8 mm
  /// (docs/measurements.md, session 46).
  double fit_limit_margin_rad = 0.1;
};

/// The scripted user's task in a scene: the cube's start pose (`X_cube0`) when it has one, else the
/// object nearest the frame centre; the script fitted to the user's own hands (`user`), so their
/// fingers can be where the device's caps are. (One place for the demo and the live session.)
/// Fails as reach_target does.
Result<std::shared_ptr<sim::RubiksTask>> make_scripted_task(const physics::World& world,
                                                    const std::optional<physics::RubiksCube>& cube,
                                                    double proxy_radius,
                                                    const std::array<hand::HandModel, 2>& user,
                                                    Pose* X_cube0, const ScriptedUserOptions& options = {});

}  // namespace spidar::session
