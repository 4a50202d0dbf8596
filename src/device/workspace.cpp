#include "spidar/device/workspace.hpp"

#include <cmath>
#include <limits>

namespace spidar::device {

Workspace device_workspace(const strings::DeviceConfig& config, double margin_m) {
  Workspace w;
  bool first = true;
  for (const auto& f : config.fingers) {
    for (int i = 0; i < f.geometry.n; ++i) {
      const Vec3& a = f.geometry.p_WA[i];
      w.lo_W = first ? a : Vec3(w.lo_W.cwiseMin(a));
      w.hi_W = first ? a : Vec3(w.hi_W.cwiseMax(a));
      first = false;
    }
  }
  if (first) w.lo_W = w.hi_W = config.p_W_centre;  // no fulcrums: only the margin around the centre
  w.lo_W.array() -= margin_m;
  w.hi_W.array() += margin_m;
  return w;
}

WorkspaceExcess workspace_excess(const Workspace& workspace, const std::array<double, 3>& p_W) {
  WorkspaceExcess e;
  for (int k = 0; k < 3; ++k) {
    const double v = p_W[k];
    if (!std::isfinite(v)) {
      e.distance_m = std::numeric_limits<double>::infinity();
      e.axis = k;
      e.limit_m = workspace.hi_W[k];
      return e;
    }
    if (v < workspace.lo_W[k] && workspace.lo_W[k] - v > e.distance_m) {
      e = {workspace.lo_W[k] - v, k, workspace.lo_W[k]};
    } else if (v > workspace.hi_W[k] && v - workspace.hi_W[k] > e.distance_m) {
      e = {v - workspace.hi_W[k], k, workspace.hi_W[k]};
    }
  }
  return e;
}

}  // namespace spidar::device
