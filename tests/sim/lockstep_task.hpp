#pragma once
// The scripted Rubik's task on the real physics, in lockstep (no threads, no device): the user's
// fingertips follow the script's goals through the simulated device's fingertip impedance and
// feel the coupling forces, one physics step at a time. Deterministic, so what depends on where
// the fingertips end up (the cube's turns, the user's hands on the caps) is checked without the
// timing of a busy machine.
#include <algorithm>
#include <functional>
#include <string>
#include <span>
#include <vector>

#include "source_path.hpp"
#include "spidar/core/pose.hpp"
#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/sim/rubiks_task.hpp"

namespace spidar::sim {

/// Called after every physics step with the run time [s], the eight fingertip caps (the device's
/// fingertips, left thumb … right ring) [m, world] and the cube.
using LockstepObserver =
    std::function<void(double t_s, std::span<const Vec3> p_W_caps, const physics::RubiksCube& cube)>;

/// Plays the task (the script with the scene's cube and proxy sizes) to its end on the scene
/// scenes/rubiks_cube.xml. `prepare` sees the task before it starts (e.g. to fit it to hands; the
/// task lives until run_lockstep returns), `observe` every step after it.
/// `shaped_fingers`: RubiksTaskParams::shaped_fingers. `scene`: another MJCF file with the cube
/// (empty: scenes/rubiks_cube.xml).
inline void run_lockstep(const std::function<void(RubiksTask&)>& prepare, const LockstepObserver& observe,
                         bool shaped_fingers = false, const std::string& scene = {}) {
  auto world = physics::World::Load(scene.empty() ? spidar::test::source("scenes/rubiks_cube.xml") : scene).value();
  auto cube = physics::RubiksCube::Attach(*world).value();
  RubiksTaskParams tp;
  tp.proxy_radius = world->params().proxy.radius;
  tp.p_W_cube = cube.core_pose().p;
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
    const Pose X = cube.core_pose();
    pose.publish({{X.p.x(), X.p.y(), X.p.z()}, {X.R.w(), X.R.x(), X.R.y(), X.R.z()}});
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

}  // namespace spidar::sim
