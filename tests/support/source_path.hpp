#pragma once
// Paths of files in the source tree (configs, scenes) for tests; SPIDAR_SOURCE_DIR is set by CMake.
#include <string>

namespace spidar::test {

inline std::string source(const std::string& rel) { return std::string(SPIDAR_SOURCE_DIR) + "/" + rel; }

}  // namespace spidar::test
