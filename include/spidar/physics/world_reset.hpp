#pragma once
/// Putting a world back to its initial state (the scene as loaded: a Rubik's cube solved at its
/// start pose), keeping the fingertip proxies where they are so the coupling does not jump.
#include "spidar/physics/world.hpp"

namespace spidar::physics {

/// Resets the simulation state (positions, velocities, time kept running) and re-places the
/// proxies at their current positions, at rest. Call from the thread that steps the world.
void reset_world(World& world);

}  // namespace spidar::physics
