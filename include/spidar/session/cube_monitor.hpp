#pragma once
/// The cube (or the object the user reaches for) as the physics thread sees it: status, pose,
/// completed turns, and scramble/reset requests from other threads.
#include <array>
#include <atomic>
#include <cstdint>
#include <optional>

#include "spidar/core/pose.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::session {

/// The cube (or, in another scene, the object the user reaches for) as the physics thread sees it.
struct CubeStatus {
  double t_s = 0;                  ///< physics time [s]
  double lift = 0;                 ///< core height above its start [m]
  double u_angle = 0, d_angle = 0; ///< top and bottom layer angles [rad]
  double u_misalign = 0;           ///< top layer's angle from its nearest click [rad]
  int turns = 0;      ///< completed quarter turns of every face
  int top_turns = 0;  ///< of them, the top layer's (U): the layer the scripted user turns
  bool present = false;  ///< the scene has a Rubik's cube (the fields above and below are its)
  bool solved = false;  ///< a cube is present and solved (false in a scene without one)
  int contacts = 0;
};

/// Counts completed quarter turns of any face: a layer that settles (within 3°) at another
/// quarter than before.
class TurnCounter {
 public:
  void update(const physics::RubiksCube& cube);
  /// Takes the faces' present quarters as the reference without counting turns (after a
  /// scramble or a reset: those are not the user's turns).
  void rebase(const physics::RubiksCube& cube);
  int turns() const { return turns_; }
  /// Quarter turns of one face ('U', 'D', 'F', 'B', 'R', 'L'); 0 for any other letter.
  int turns_of(char face) const;

 private:
  std::array<int, 6> quarter_{};
  std::array<int, 6> per_face_{};
  int turns_ = 0;
};

/// Watches the cube from the physics thread (call `before_step` there): publishes its status and
/// pose, and carries out scramble and reset requests made from other threads (the GUI).
class CubeMonitor {
 public:
  /// `cube` may be empty (a scene without a Rubik's cube); it must outlive the monitor.
  CubeMonitor(std::optional<physics::RubiksCube>* cube, const Pose& X_cube0);
  void before_step(physics::World& w);
  core::Latest<CubeStatus>& status() { return status_; }
  core::Latest<sim::CubePoseSample>& pose() { return pose_; }
  /// Any thread: scramble with `n` random quarter turns at the next physics step.
  void request_scramble(int n) { scramble_.store(n, std::memory_order_release); }
  /// Any thread: the world back to its initial state at the next physics step (the cube solved
  /// at its start pose; the fingertip proxies stay where they are).
  void request_reset() { reset_.store(true, std::memory_order_release); }
  bool has_cube() const { return cube_->has_value(); }

 private:
  std::optional<physics::RubiksCube>* cube_;
  Pose X_cube0_;
  TurnCounter turns_;
  core::Latest<CubeStatus> status_;
  core::Latest<sim::CubePoseSample> pose_;
  std::atomic<int> scramble_{0};
  std::atomic<bool> reset_{false};
  std::uint64_t scramble_seed_ = 1;
};

}  // namespace spidar::session
