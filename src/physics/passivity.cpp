#include "spidar/physics/passivity.hpp"

#include <algorithm>

namespace spidar::physics {

Vec3 PassivityPort::step(const Vec3& f_W, const Vec3& v_W, double dt) {
  Vec3 f = f_W;
  double e = stats_.energy - f.dot(v_W) * dt;
  const double v2 = v_W.squaredNorm();
  if (e < 0 && control_ && v2 > 1e-12 && dt > 0) {
    // α such that the step's energy brings E back to zero: E + α v² dt = 0.
    const double alpha = std::min(-e / (v2 * dt), max_damping_);
    f -= alpha * v_W;
    stats_.dissipated += alpha * v2 * dt;
    ++stats_.active_steps;
    e = stats_.energy - f.dot(v_W) * dt;
  }
  stats_.energy = e;
  stats_.min_energy = std::min(stats_.min_energy, e);
  return f;
}

}  // namespace spidar::physics
