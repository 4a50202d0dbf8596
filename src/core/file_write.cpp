#include "spidar/core/file_write.hpp"

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "spidar/core/atomic_write.hpp"
#include "spidar/core/file_read.hpp"

namespace spidar::core {

std::string keep_previous_version(const std::string& path) {
  namespace fs = std::filesystem;
  if (!fs::exists(path)) return "";
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  std::string backup = path + ".bak-" + stamp;
  for (int k = 2; fs::exists(backup); ++k)
    backup = path + ".bak-" + stamp + "-" + std::to_string(k);
  std::error_code ec;
  fs::copy_file(path, backup, ec);
  if (ec)
    throw FileError(path, "cannot keep the previous version as " + backup + ": " + ec.message());
  return backup;
}

std::string replace_file_keeping_previous(const std::string& path, const std::string& text) {
  // The previous version beside the file a symbolic link names; the new one written whole or
  // not at all, through the link (the link stays a link).
  const std::string backup = keep_previous_version(resolve_symlinks(path));
  write_file_atomic(path, text);
  return backup;
}

}  // namespace spidar::core
