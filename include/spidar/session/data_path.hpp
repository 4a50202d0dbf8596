#pragma once
/// Where a data file given relative to the project (e.g. "configs/spidar8.yaml") is found.
#include <string>

namespace spidar::session {

/// `path` as given if it exists, else under the installed data directory (if there), else as
/// given (its loader then reports it missing).
std::string resolve_data_path(const std::string& path);

}  // namespace spidar::session
