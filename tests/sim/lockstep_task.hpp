#pragma once
// The scripted Rubik's task on the real physics, in lockstep (no threads, no device): the user's
// fingertips follow the script's goals through the simulated device's fingertip impedance and
// feel the coupling forces, one physics step at a time. Deterministic, so what depends on where
// the fingertips end up (the cube's turns, the user's hands on the caps) is checked without the
// timing of a busy machine.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <span>
#include <vector>

#include "source_path.hpp"
#include "spidar/core/pose.hpp"
#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/user_hands.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::sim {

/// Called after every physics step with the run time [s], the eight fingertip caps (the device's
/// fingertips, left thumb … right ring) [m, world] and the cube.
using LockstepObserver =
    std::function<void(double t_s, std::span<const Vec3> p_W_caps, const physics::RubiksCube& cube)>;

/// The scene (empty: scenes/rubiks_cube.xml) loaded with its cube, and the task's parameters for
/// it: the world's proxy radius and the cube's start place.
struct LockstepScene {
  std::unique_ptr<physics::World> world;
  physics::RubiksCube cube;
  RubiksTaskParams params;
};
inline LockstepScene load_lockstep_scene(const std::string& scene) {
  auto world = physics::World::Load(scene.empty() ? spidar::test::source("scenes/rubiks_cube.xml") : scene).value();
  auto cube = physics::RubiksCube::Attach(*world).value();
  RubiksTaskParams tp;
  tp.proxy_radius = world->params().proxy.radius;
  tp.p_W_cube = cube.core_pose().p;
  return {std::move(world), std::move(cube), tp};
}

/// The top layer's angle in quarter turns, rounded.
inline int u_quarter_turns(const physics::RubiksCube& cube) {
  return static_cast<int>(std::lround(cube.face_angle('U') / (units::kPi / 2)));
}

/// The hands (left, right) of the user in hands YAML `hands_file` (a path in the source tree): its
/// profile `user`, else its first.
inline std::array<hand::HandModel, 2> profile_hands(const std::string& hands_file) {
  const auto profiles = hand::load_hand_profiles(spidar::test::source(hands_file));
  const hand::HandProfile& profile = profiles.find("user") ? *profiles.find("user") : profiles.profiles.at(0);
  return {profile.model(hand::Side::kLeft), profile.model(hand::Side::kRight)};
}

/// The simulated user's hands posed on the device's caps at the camera's rate (30 frames per
/// second), as the demo's camera thread poses them, from a lockstep run's observer.
class CameraRateUser {
 public:
  explicit CameraRateUser(const std::array<hand::HandModel, 2>& hands) : hands_(hands) {}
  /// Makes the hands for `task` (after it is fitted; it must outlive them).
  void start(const RubiksTask& task) { user_ = std::make_unique<UserHands>(hands_, task); }
  /// Poses the hands on `p_W_caps` at run time t [s] when a frame is due; returns whether it did.
  bool pose(double t_s, std::span<const Vec3> p_W_caps) {
    if (t_s + 1e-9 < next_frame_s_) return false;
    next_frame_s_ += 1.0 / 30;
    user_->update(t_s, p_W_caps);
    return true;
  }
  const UserHands& hands() const { return *user_; }

 private:
  std::array<hand::HandModel, 2> hands_;
  std::unique_ptr<UserHands> user_;
  double next_frame_s_ = 0;
};

/// Publishes the cube's present pose for the task to track.
inline void publish_cube_pose(const physics::RubiksCube& cube, core::Latest<CubePoseSample>& pose) {
  const Pose X = cube.core_pose();
  pose.publish({{X.p.x(), X.p.y(), X.p.z()}, {X.R.w(), X.R.x(), X.R.y(), X.R.z()}});
}

/// Plays the task (the script with the scene's cube and proxy sizes) to its end on the scene
/// scenes/rubiks_cube.xml. `prepare` sees the task before it starts (e.g. to fit it to hands; the
/// task lives until run_lockstep returns), `observe` every step after it.
/// `shaped_fingers`: RubiksTaskParams::shaped_fingers. `scene`: another MJCF file with the cube
/// (empty: scenes/rubiks_cube.xml).
inline void run_lockstep(const std::function<void(RubiksTask&)>& prepare, const LockstepObserver& observe,
                         bool shaped_fingers = false, const std::string& scene = {}) {
  auto [world, cube, tp] = load_lockstep_scene(scene);
  tp.shaped_fingers = shaped_fingers;
  RubiksTask task(tp);
  if (prepare) prepare(task);
  core::Latest<CubePoseSample> pose;
  task.track(&pose);
  std::vector<Vec3> x(8), v(8, Vec3::Zero()), goal(8);
  task.goals(0.0, goal);
  x = goal;
  world->place_proxies(x);
  const device::FingertipImpedance imp;  // the simulated device's human fingertip
  std::vector<device::FingertipHold> hold(8);
  const double dt = world->timestep();
  for (int s = 0; s * dt < tp.duration; ++s) {
    publish_cube_pose(cube, pose);
    task.goals(s * dt, goal);
    if (!task.holds(hold)) std::fill(hold.begin(), hold.end(), device::FingertipHold{});
    const auto f_proxy = world->coupling_forces();  // the fingertip feels the opposite
    for (std::size_t i = 0; i < 8; ++i)
      for (int k = 0; k < 4; ++k)  // sub-steps of dt / 4, as the simulated device's
        device::step_fingertip(imp, device::sanitized(hold[i]), goal[i], -f_proxy[i], dt / 4, x[i], v[i]);
    world->step(x, v);
    if (observe) observe(s * dt, x, cube);
  }
}

/// run_lockstep through the simulated device (configs/spidar8.yaml): what the demo adds to the
/// coupling, in lockstep. Every 1 ms the device advances (the user's fingertips follow the goals,
/// pulled by the strings' tensions), one servo cycle measures the caps from the encoder counts and
/// turns the coupling forces (sim::HapticForces, against the proxies of the previous physics step)
/// into tensions, and the physics steps on the measured fingertips. So the user feels only what
/// three pulling strings per finger can display, as in the demo; the threads' timing is left out.
/// `observe` as run_lockstep's, with the true caps. `ring_on_side`: RubiksTaskParams::ring_on_side.
inline void run_lockstep_device(const std::function<void(RubiksTask&)>& prepare, const LockstepObserver& observe,
                                const std::string& scene = {}, bool ring_on_side = false) {
  auto [world, cube, tp] = load_lockstep_scene(scene);
  const auto cfg = strings::load_device_config(spidar::test::source("configs/spidar8.yaml"));
  tp.ring_on_side = ring_on_side;
  auto task = std::make_shared<RubiksTask>(tp);
  if (prepare) prepare(*task);
  core::Latest<CubePoseSample> pose;
  task->track(&pose);
  const double dt = world->timestep();
  device::SimulatedSpidarParams dp;
  dp.fixed_step_s = dt;
  device::SimulatedSpidar dev(cfg, dp, task);
  if (!dev.open().ok()) return;
  dev.clear_safe_state();  // as the servo loop does once it runs: a device opens in its safe state
  device::ServoCycle cycle(cfg, dev.info());
  HapticForces bridge(world->params().coupling, 1.0 / dt);
  device::EncoderReading reading;
  device::FingertipSample sample;
  device::ForceFrame force;
  std::vector<std::int32_t> commands(static_cast<std::size_t>(cfg.string_count()), dev.info().command_min);
  std::vector<Vec3> p(8), v(8, Vec3::Zero());
  bool placed = false;
  for (int s = 0; s * dt < tp.duration; ++s) {
    const std::int64_t t_ns = static_cast<std::int64_t>(s) * 1000000;  // the lockstep's clock, not the host's
    publish_cube_pose(cube, pose);
    reading.repeats = 0;
    if (!dev.read(reading).ok()) return;
    reading.host_time_ns = t_ns;
    cycle.measure(reading, sample);
    bridge.forces(sample, force);
    cycle.command(force, false, sample, commands);
    if (!dev.write(commands).ok()) return;
    const auto target = bridge.targets().read();  // the measured fingertips, velocities filtered
    for (int f = 0; f < 8; ++f) {
      p[f] = device::fingertip_position(sample, f);
      if (target) v[f] = Vec3(target->v_W[f][0], target->v_W[f][1], target->v_W[f][2]);
    }
    if (!placed) world->place_proxies(p), placed = true;
    world->step(p, v);
    // What the physics thread publishes after its step.
    const ProxyFrame frame = proxy_frame(*world, 8, t_ns, static_cast<std::uint64_t>(s) + 1);
    bridge.proxies().publish(frame);
    if (observe) observe(s * dt, dev.truth().p_W_fingertip, cube);
  }
}

}  // namespace spidar::sim
