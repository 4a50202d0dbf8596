#pragma once
/// Pieces of a mixed-reality session shared by the live application (`run`, `replay`) and, in
/// time, the demo (`demo`): camera scaling, hand profiles, where the scripted user reaches, and
/// the cube's state as the physics thread sees it.
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "spidar/core/pose.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::app {

/// The camera with its intrinsics scaled to a w×h image (pixel centres kept consistent).
vision::Camera scaled_camera(const vision::Camera& c, int w, int h);

/// Both hands (left, right) of profile `profile` in a hands YAML. With `first_if_missing`, a
/// missing profile falls back to the file's first one; otherwise UsageError naming the file.
std::array<hand::HandModel, 2> hand_models(const std::string& path, const std::string& profile,
                                           bool first_if_missing);

/// Where the scripted user reaches in a scene without a cube: the non-static object nearest the
/// frame centre (its centre and half size), else the centre itself.
void reach_target(const SceneSnapshot& scene, sim::RubiksTaskParams* tp);

/// The scripted user's task in a scene: the cube's start pose (`X_cube0`) when it has one, else the
/// object nearest the frame centre; the script fitted to the user's own hands (`user`), so their
/// fingers can be where the device's caps are. (One place for the demo and the live session.)
/// `deadline_s` > 0: the run time by which the user must be done (its retries must fit).
std::shared_ptr<sim::RubiksTask> make_scripted_task(const physics::World& world,
                                                    const std::optional<physics::RubiksCube>& cube,
                                                    double proxy_radius,
                                                    const std::array<hand::HandModel, 2>& user,
                                                    Pose* X_cube0, double deadline_s = 0);

/// The servo loop's timing between two camera frames.
struct ServoTiming {
  double rate_hz = 0;        ///< cycles per second since the previous frame (0: not known yet)
  double jitter_max_us = 0;  ///< largest deviation of a period from the nominal one [µs]
};
/// From the loop's published samples, newest first (ServoLoop::newest_samples), those newer than
/// `*last_t_ns` (the newest seen at the previous frame; updated). `rate_hz`: nominal rate.
ServoTiming servo_timing_since(std::span<const device::FingertipSample> newest_first, double rate_hz,
                               std::int64_t* last_t_ns);

/// The cube (or, in another scene, the object the user reaches for) as the physics thread sees it.
struct CubeStatus {
  double t_s = 0;
  double lift = 0;
  double u_angle = 0, d_angle = 0;
  int turns = 0;
  bool solved = true;
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

 private:
  std::array<int, 6> quarter_{};
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

}  // namespace spidar::app
