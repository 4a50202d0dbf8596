#pragma once
/// Render geometry of a posed hand: one capsule per bone and a box for the palm, as a plain list
/// of shapes in world coordinates. (Module-local types; a renderer or a future
/// core::SceneSnapshot converts them.)
#include <vector>

#include "spidar/core/pose.hpp"
#include "spidar/hand/kinematics.hpp"

namespace spidar::hand {

/// A capsule: the segment p_W_a → p_W_b swept by a sphere of `radius` [m], world.
struct Capsule {
  Vec3 p_W_a = Vec3::Zero();
  Vec3 p_W_b = Vec3::Zero();
  double radius = 0.0;
  int finger = -1;   ///< Finger (parameters.hpp)
  int segment = -1;  ///< 0 = metacarpal, 1.. = phalanges proximal to distal
};

/// An oriented box: pose of the box frame B in world and half extents along B's axes [m].
struct Box {
  Pose X_WB;
  Vec3 half_extents = Vec3::Zero();
};

struct HandRenderShapes {
  Side side = Side::kRight;
  std::vector<Capsule> capsules;  ///< 4 per finger, 3 for the thumb: 19
  std::vector<Box> boxes;         ///< the palm
};

/// Shapes of the hand posed by `params`. Each distal capsule ends one radius short of the bone's
/// end, so its rounded cap reaches the tip.
HandRenderShapes hand_render_shapes(const HandModel& model, const HandParams& params);

/// The same from already computed forward kinematics of `params`.
HandRenderShapes hand_render_shapes(const HandModel& model, const HandParams& params,
                                    const HandPoints& points);

}  // namespace spidar::hand
