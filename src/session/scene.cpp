#include "spidar/session/scene.hpp"

#include "spidar/session/scripted_task.hpp"

namespace spidar::session {

Result<std::unique_ptr<Scene>> Scene::load(const std::string& path,
                                           const std::array<hand::HandModel, 2>& user,
                                           const ScriptedUserOptions& user_options) {
  auto s = std::make_unique<Scene>();
  auto world_r = physics::World::Load(path, s->params);
  if (!world_r) return world_r.error();
  s->world = std::move(world_r).value();
  if (auto cube_r = physics::RubiksCube::Attach(*s->world)) s->cube = std::move(cube_r).value();
  Pose X_cube0;
  auto task = make_scripted_task(*s->world, s->cube, s->params.proxy.radius, user, &X_cube0,
                                 user_options);
  if (!task) return task.error();
  s->task = std::move(task).value();
  s->monitor = std::make_unique<CubeMonitor>(&s->cube, X_cube0);
  if (s->cube) s->task->track(&s->monitor->pose());  // the user watches the cube
  return s;
}

std::array<Vec3, 2> Scene::initial_r_W_hand() const {
  return {task->nominal(0.0, hand::Side::kLeft).r_W_hand(),
          task->nominal(0.0, hand::Side::kRight).r_W_hand()};
}

}  // namespace spidar::session
