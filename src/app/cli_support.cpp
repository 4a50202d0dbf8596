#include "cli_support.hpp"

#include "spidar/core/file_read.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace spidar::app {

int find_finger(const strings::DeviceConfig& cfg, const std::string& finger) {
  const int n = static_cast<int>(cfg.fingers.size());
  int index = -1;
  const char* end = finger.data() + finger.size();
  auto [ptr, ec] = std::from_chars(finger.data(), end, index);
  if (ec == std::errc() && ptr == end) {
    if (index >= 0 && index < n) return index;
  } else {
    for (int i = 0; i < n; ++i)
      if (cfg.fingers[i].name == finger) return i;
  }
  std::string names;
  for (int i = 0; i < n; ++i) {
    names += (i ? ", " : "") + std::to_string(i) + " (" + cfg.fingers[i].name + ")";
  }
  throw UsageError("--finger " + finger + ": unknown finger in " + cfg.source +
                   "; expected one of " + names);
}


void require_range(double x, double lo, double hi, std::string_view option, std::string_view unit) {
  if (x >= lo && x <= hi) return;
  std::ostringstream os;
  os << option << ": expected " << lo << " to " << hi << (unit.empty() ? "" : " ") << unit << ", got " << x;
  throw UsageError(os.str());
}

void require_path(const std::string& path, std::string_view option, std::string_view what) {
  if (!path.empty()) return;
  throw UsageError(std::string(option) + ": expected " + std::string(what) + ", got an empty path");
}

void make_output_dir(const std::string& dir, std::string_view option) {
  require_path(dir, option, "a directory");
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!ec && !fs::is_directory(dir, ec)) ec = std::make_error_code(std::errc::not_a_directory);
  if (ec)
    throw UsageError(std::string(option) + ": cannot make the output directory '" +
                     core::printable_for_message(dir) + "': " + ec.message());
}

CLI::Validator seed_check() {
  return CLI::Validator(
      [](std::string& s) -> std::string {
        const std::string expected = "expected a whole number 0 to " + std::to_string(kMaxSeed) + ", got '" + s + "'";
        if (s.empty() || s.size() > 10) return expected;
        std::uint64_t v = 0;
        const char* end = s.data() + s.size();
        auto [ptr, ec] = std::from_chars(s.data(), end, v);
        if (ec != std::errc() || ptr != end || v > kMaxSeed) return expected;
        return {};
      },
      "SEED 0.." + std::to_string(kMaxSeed));
}

}  // namespace spidar::app
