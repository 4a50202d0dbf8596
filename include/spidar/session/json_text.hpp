#pragma once
/// JSON text for output (reports, summaries on stdout). Text that is not UTF-8 (a path given on
/// the command line, say) is written with U+FFFD in place of its bad bytes rather than throwing,
/// which would lose a finished run's results; configuration text is checked where it is read
/// (core::ConfigNode::as_string).
#include <nlohmann/json.hpp>
#include <string>

namespace spidar::session {

/// `j` as text, `indent` spaces a level (−1: one line, as nlohmann::json::dump).
inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace spidar::session
