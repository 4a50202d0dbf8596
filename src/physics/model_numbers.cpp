#include "model_numbers.hpp"

#include <mujoco/mjxmacro.h>

#include <cmath>
#include <sstream>
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

std::string first_implausible_number(const mjModel* m) {
  std::ostringstream os;
  // A vector's components are named x, y, z; a single number has no index.
  auto beyond = [&](const std::string& name, const mjtNum* values, int count, double bound, const char* unit) {
    for (int i = 0; i < count; ++i) {
      if (std::abs(values[i]) > bound) {
        os << name << (count == 3 ? std::string(" ") + "xyz"[i] : std::string()) << " is " << values[i]
           << "; expected at most " << bound << " " << unit << " in magnitude";
        return true;
      }
    }
    return false;
  };
  if (beyond("option gravity", m->opt.gravity, 3, 1e3, "m/s²") || beyond("option wind", m->opt.wind, 3, 1e3, "m/s") ||
      beyond("option magnetic", m->opt.magnetic, 3, 1e3, "T") ||
      beyond("option density", &m->opt.density, 1, 1e5, "kg/m³") ||
      beyond("option viscosity", &m->opt.viscosity, 1, 1e5, "Pa·s"))
    return os.str();
  for (int b = 0; b < m->nbody; ++b) {
    const char* name = mj_id2name(m, mjOBJ_BODY, b);
    const std::string body = name && *name ? "body '" + std::string(name) + "'" : "body " + std::to_string(b) + " (unnamed)";
    if (beyond(body + " mass", m->body_mass + b, 1, 1e6, "kg") || beyond(body + " pos", m->body_pos + 3 * b, 3, 1e3, "m"))
      return os.str();
  }
  return {};
}

}  // namespace spidar::physics
