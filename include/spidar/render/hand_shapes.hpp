#pragma once
/// The hand model's render geometry (hand/render_geometry.hpp: a capsule per bone, a box for the
/// palm) as SceneSnapshot shapes tagged with their hand and finger, for the renderer's hand
/// targets.
#include <array>

#include "spidar/core/scene_snapshot.hpp"
#include "spidar/hand/render_geometry.hpp"

namespace spidar::render {

/// Capsule along z of a frame whose origin is the segment's midpoint: Shape::size = (radius,
/// half length, 0). A degenerate segment (a = b) becomes a sphere-like capsule of half length 0.
Shape capsule_shape(const Vec3& p_W_a, const Vec3& p_W_b, double radius);

/// Appends the shapes of one hand: capsules with `finger` = their finger, the palm box with
/// finger −1; `hand` = 0 (left) or 1 (right) from shapes.side.
void append_hand_shapes(const hand::HandRenderShapes& shapes, SceneSnapshot* scene,
                        const std::array<float, 4>& rgba = {0.85f, 0.62f, 0.50f, 1.f});

}  // namespace spidar::render
