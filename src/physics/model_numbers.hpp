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

}  // namespace spidar::physics
