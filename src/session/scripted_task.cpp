#include "spidar/session/scripted_task.hpp"

#include <algorithm>

namespace spidar::session {

void reach_target(const SceneSnapshot& scene, sim::RubiksTaskParams* tp) {
  double best = 1e9;
  for (const Shape& s : scene.shapes) {
    if (s.body <= 0 || s.hand >= 0) continue;
    const double d = s.X_WS.p.norm();
    if (d < best) {
      best = d;
      tp->p_W_cube = s.X_WS.p;
      tp->half = std::clamp(s.size.maxCoeff(), 0.01, 0.05);
      tp->pitch = tp->half * 2.0 / 3.0;
    }
  }
}

std::shared_ptr<sim::RubiksTask> make_scripted_task(const physics::World& world,
                                                    const std::optional<physics::RubiksCube>& cube,
                                                    double proxy_radius,
                                                    const std::array<hand::HandModel, 2>& user,
                                                    Pose* X_cube0, const ScriptedUserOptions& options) {
  sim::RubiksTaskParams tp;
  tp.proxy_radius = proxy_radius;
  tp.has_cube = cube.has_value();
  tp.shaped_fingers = options.shaped_fingers;
  if (options.deadline_s > 0) tp.deadline = options.deadline_s;
  *X_cube0 = Pose{};
  if (cube) {
    *X_cube0 = cube->core_pose();
    tp.p_W_cube = X_cube0->p;
  } else {
    SceneSnapshot s0;
    world.snapshot(s0, false);
    reach_target(s0, &tp);
    X_cube0->p = tp.p_W_cube;
  }
  auto task = std::make_shared<sim::RubiksTask>(tp);
  task->fit_to_hands(user);
  return task;
}

}  // namespace spidar::session
