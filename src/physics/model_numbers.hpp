#pragma once
// Inside the physics module only: checks on a compiled MuJoCo model's numbers.
#include <string>

#include <mujoco/mujoco.h>

namespace spidar::physics {

/// The first non-finite number among the compiled model's real-valued arrays (MuJoCo's
/// MJMODEL_POINTERS: positions, sizes, masses, ranges, colours, …) and its physical options
/// (gravity, wind, magnetic field, density, viscosity), e.g. "geom_size[3]"; empty if all are
/// finite. MuJoCo 2.2.2 compiles "nan" in an MJCF attribute without a word.
std::string first_non_finite_number(const mjModel* m);

/// The first of the physical options and bodies' numbers that is finite but beyond what any scene
/// on a table can mean, so large that the simulation would overflow (a gravity of 1e308 turns the
/// cube's state to nan): gravity, wind and magnetic field beyond 1000 (m/s², m/s, T) in any
/// component, density or viscosity beyond 1e5, a body's mass beyond 1e6 kg or its position
/// relative to its parent body beyond 1000 m (MJCF's `pos`; nested bodies could sum further, a
/// case no scene file writes by accident). A message naming the number (a body by its name, or
/// "body 3 (unnamed)"), its value and the bound; empty if none.
std::string first_implausible_number(const mjModel* m);

}  // namespace spidar::physics
