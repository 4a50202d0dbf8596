#include "spidar/physics/world_reset.hpp"

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

namespace spidar::physics {

void reset_world(World& world) {
  std::vector<Vec3> p_W;
  p_W.reserve(world.proxies().size());
  for (const ProxyState& p : world.proxies()) p_W.push_back(p.p_W);
  mjData* d = world.data();
  const mjModel* m = world.model();
  const double t = d->time;
  mj_resetData(m, d);
  d->time = t;  // world time runs on (the physics thread paces by it)
  mj_forward(m, d);
  world.place_proxies(p_W);
}

}  // namespace spidar::physics
