#include "model_numbers.hpp"

#include <mujoco/mjxmacro.h>

#include <cmath>
#include <type_traits>

namespace spidar::physics {
namespace {

template <typename T>
bool all_finite(const T* values, int count, int* bad) {
  if constexpr (std::is_floating_point_v<T>) {
    for (int i = 0; i < count; ++i) {
      if (!std::isfinite(values[i])) {
        *bad = i;
        return false;
      }
    }
  }
  return true;
}

}  // namespace

std::string first_non_finite_number(const mjModel* m) {
  int bad = 0;
  // The array sizes MJMODEL_POINTERS names (nbody, nq, nuser_geom, …): mjModel's int fields.
#define X(name) [[maybe_unused]] const int name = m->name;
  MJMODEL_INTS
#undef X
#define X(type, name, nr, nc)                                                  \
  if (!all_finite<type>(m->name, (nr) * (nc), &bad)) {                         \
    return std::string(#name) + "[" + std::to_string(bad) + "]";              \
  }
  MJMODEL_POINTERS
#undef X
  const struct {
    const char* name;
    const mjtNum* values;
    int count;
  } options[] = {{"option gravity", m->opt.gravity, 3},   {"option wind", m->opt.wind, 3},
                 {"option magnetic", m->opt.magnetic, 3}, {"option density", &m->opt.density, 1},
                 {"option viscosity", &m->opt.viscosity, 1}};
  for (const auto& o : options) {
    if (!all_finite(o.values, o.count, &bad)) return std::string(o.name) + "[" + std::to_string(bad) + "]";
  }
  return {};
}

}  // namespace spidar::physics
