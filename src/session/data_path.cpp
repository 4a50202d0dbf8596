#include "spidar/session/data_path.hpp"

#include <filesystem>

namespace spidar::session {

std::string resolve_data_path(const std::string& path) {
  namespace fs = std::filesystem;
  if (fs::exists(path)) return path;
#ifdef SPIDAR_DATA_DIR
  const fs::path installed = fs::path(SPIDAR_DATA_DIR) / path;
  if (fs::exists(installed)) return installed.string();
#endif
  return path;  // the loader reports it missing
}

}  // namespace spidar::session
