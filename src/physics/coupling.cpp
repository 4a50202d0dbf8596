#include "spidar/physics/coupling.hpp"

#include <cmath>

namespace spidar::physics {

Vec3 coupling_force(const CouplingParams& c, const Vec3& p_F, const Vec3& v_F, const Vec3& p_P,
                    const Vec3& v_P) {
  Vec3 f = c.stiffness * (p_F - p_P) + c.damping * (v_F - v_P);
  const double n = f.norm();
  if (!(n <= c.max_force)) f *= (n > 0 && std::isfinite(n)) ? c.max_force / n : 0.0;
  return f;
}

Vec3 local_proxy_position(const ProxyState& proxy, double dt) {
  Vec3 p = proxy.p_W + proxy.v_W * dt;
  // A few passes resolve corners formed by two or three planes.
  for (int pass = 0; pass < 3; ++pass) {
    for (int k = 0; k < proxy.plane_count; ++k) {
      const auto& pl = proxy.planes[k];
      const double d = pl.n_W.dot(p) - pl.offset;
      if (d < 0) p -= d * pl.n_W;
    }
  }
  return p;
}

}  // namespace spidar::physics
