#pragma once
/// A check before writing JSON output (reports, summaries): every number must be finite.
#include <nlohmann/json.hpp>
#include <string_view>

namespace spidar::session {

/// SpidarError naming the JSON path (e.g. "/haptic/jitter_p99_us") of the first number in `j`
/// that is NaN or infinite, which nlohmann::json would write as null; `what` names the output
/// ("report.json"). Call before writing any JSON.
void require_finite_json(const nlohmann::json& j, std::string_view what);

}  // namespace spidar::session
