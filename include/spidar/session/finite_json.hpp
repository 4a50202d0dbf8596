#pragma once
/// Writing JSON output (reports, summaries): every number must be finite; vectors as arrays.
#include <nlohmann/json.hpp>
#include <string_view>

#include "spidar/core/types.hpp"

namespace spidar::session {

/// SpidarError naming the JSON path (e.g. "/haptic/jitter_p99_us") of the first number in `j`
/// that is NaN or infinite, which nlohmann::json would write as null, or of the first null;
/// `what` names the output ("report.json"). Call before writing any JSON.
void require_finite_json(const nlohmann::json& j, std::string_view what);

/// A vector as a JSON array [x, y, z].
inline nlohmann::json to_json(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

}  // namespace spidar::session
