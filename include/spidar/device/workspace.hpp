#pragma once
/// The volume a string device can measure a fingertip in: the axis-aligned box spanned by all
/// its fulcrums (the frame's pulleys; SPIDAR-8: 0.73 × 0.57 × 0.46 m), grown on every side by a
/// margin. A fingertip inside the frame is always inside it; a solved position far outside it
/// means the lengths it came from are wrong (an encoder glitch, a broken string, a bad
/// calibration), not that the finger is there.
#include <array>

#include "spidar/core/types.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device {

struct Workspace {
  Vec3 lo_W = Vec3::Zero();  ///< lowest corner [m], world (fulcrums' minimum − margin)
  Vec3 hi_W = Vec3::Zero();  ///< highest corner [m], world (fulcrums' maximum + margin)
};

/// The fulcrums' bounding box grown by `margin_m` [m] (≥ 0) on every side.
Workspace device_workspace(const strings::DeviceConfig& config, double margin_m);

/// How far a point lies outside a workspace: the axis with the largest excess.
struct WorkspaceExcess {
  double distance_m = 0.0;  ///< [m] beyond the box along `axis`; 0 inside; +inf if not finite
  int axis = -1;            ///< 0, 1, 2 = x, y, z; −1 inside
  double limit_m = 0.0;     ///< the box face that was crossed, along `axis` [m]
};
WorkspaceExcess workspace_excess(const Workspace& workspace, const std::array<double, 3>& p_W);

}  // namespace spidar::device
