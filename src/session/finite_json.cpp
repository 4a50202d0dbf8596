#include "spidar/session/finite_json.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::session {

namespace {

/// The first non-finite number or null under `j`, as a JSON pointer ("" if none); a null reads
/// as NaN in `value`.
bool find_non_finite(const nlohmann::json& j, const std::string& path, std::string* where, double* value) {
  if (j.is_null()) {
    *where = path.empty() ? "/" : path;
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  if (j.is_number_float()) {
    const double v = j.get<double>();
    if (std::isfinite(v)) return false;
    *where = path.empty() ? "/" : path;
    *value = v;
    return true;
  }
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (find_non_finite(*it, path + "/" + it.key(), where, value)) return true;
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      if (find_non_finite(j[i], path + "/" + std::to_string(i), where, value)) return true;
    }
  }
  return false;
}

}  // namespace

void require_finite_json(const nlohmann::json& j, std::string_view what) {
  std::string where;
  double v = 0;
  if (!find_non_finite(j, "", &where, &v)) return;
  std::ostringstream os;
  os << std::string(what) << ": " << where << " is " << v
     << " (a bug: every number written must be finite and every value present; JSON would show "
        "it as null)";
  throw SpidarError(os.str());
}

}  // namespace spidar::session
