#include "cli_support.hpp"

#include "spidar/core/file_read.hpp"

#include <algorithm>
#include <charconv>
#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace spidar::app {

int find_finger(const strings::DeviceConfig& cfg, const std::string& finger, std::string_view option) {
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
  throw UsageError(std::string(option) + " " + core::printable_for_message(finger) + ": unknown finger in " +
                   cfg.source + "; expected one of " + names);
}

std::vector<int> parse_finger_list(const strings::DeviceConfig& cfg, const std::string& list, std::string_view option) {
  std::vector<int> fingers;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    std::string item = list.substr(begin, end - begin);
    // "0, 1": the blanks around an item are not part of its name.
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    if (item.empty())
      throw UsageError(std::string(option) + " " + core::printable_for_message(list) +
                       ": expected comma-separated finger names or indices, got an empty item at character " +
                       std::to_string(begin + 1));
    const int f = find_finger(cfg, item, option);
    if (std::find(fingers.begin(), fingers.end(), f) != fingers.end())
      throw UsageError(std::string(option) + " " + core::printable_for_message(list) + ": finger " +
                       std::to_string(f) + " (" + cfg.fingers[static_cast<std::size_t>(f)].name +
                       ") is named twice; expected each finger at most once");
    fingers.push_back(f);
    begin = end + 1;
  }
  return fingers;
}


namespace {

/// lo <= x <= hi, and not subnormal (NaN fails).
bool in_range(double x, double lo, double hi) { return x >= lo && x <= hi && std::fpclassify(x) != FP_SUBNORMAL; }

/// ", got X" with a note when X is subnormal (in range, but no value a user means).
std::string got_text(double x) {
  std::ostringstream os;
  os << ", got " << x;
  if (std::fpclassify(x) == FP_SUBNORMAL) os << " (too small to be a value: give 0 or at least 1e-300)";
  return os.str();
}

}  // namespace

void require_range(double x, double lo, double hi, std::string_view option, std::string_view unit) {
  if (in_range(x, lo, hi)) return;
  std::ostringstream os;
  os << option << ": expected " << lo << " to " << hi << (unit.empty() ? "" : " ") << unit << got_text(x);
  throw UsageError(os.str());
}

void require_above(double x, double lo, double hi, std::string_view option, std::string_view unit) {
  if (x > lo && in_range(x, lo, hi)) return;
  std::ostringstream os;
  os << option << ": expected more than " << lo << " and at most " << hi << (unit.empty() ? "" : " ") << unit
     << got_text(x);
  throw UsageError(os.str());
}

void require_path(const std::string& path, std::string_view option, std::string_view what) {
  if (!path.empty()) return;
  throw UsageError(std::string(option) + ": expected " + std::string(what) + ", got an empty path");
}

namespace {

/// UsageError unless the nearest existing parent of `absolute` is a folder this user may write
/// into (it will hold the new file or folder).
void require_writable_parent(const std::filesystem::path& absolute, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path parent = absolute.parent_path();
  while (!parent.empty() && parent != parent.root_path() && !fs::exists(parent, ec)) parent = parent.parent_path();
  const std::string shown = core::printable_for_message(parent.string());
  if (!fs::is_directory(parent, ec)) throw UsageError(what + ": cannot be made: " + shown + " is not a folder");
  if (::access(parent.c_str(), W_OK | X_OK) != 0)
    throw UsageError(what + ": cannot be made: this user cannot write into " + shown);
}

std::filesystem::path resolved(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (!ec) absolute = fs::weakly_canonical(absolute, ec);
  if (ec) throw UsageError(what + ": cannot resolve the path: " + ec.message());
  return absolute;
}

}  // namespace

void check_output_dir(const std::string& dir, std::string_view option) {
  require_path(dir, option, "a directory");
  namespace fs = std::filesystem;
  const std::string what = std::string(option) + " " + core::printable_for_message(dir);
  const fs::path absolute = resolved(dir, what);
  std::error_code ec;
  if (absolute == absolute.root_path())
    throw UsageError(what + ": is the filesystem's root; expected a folder of its own for the outputs (e.g. out/)");
  if (!fs::exists(absolute, ec)) return require_writable_parent(absolute, what);
  if (!fs::is_directory(absolute, ec))
    throw UsageError(what + ": exists and is not a folder; expected a folder for the outputs");
  if (::access(absolute.c_str(), W_OK | X_OK) != 0) throw UsageError(what + ": is a folder this user cannot write into");
  // An output file's name taken by something else (a folder called report.json, a FIFO): found
  // now rather than after the run has written its other files. The outputs are .json, .csv,
  // .png, .mp4 and .avi files; a folder holding very many entries is scanned in part.
  int seen = 0;
  for (fs::directory_iterator it(absolute, ec); !ec && it != fs::directory_iterator() && seen < 10000; it.increment(ec), ++seen) {
    const std::string ext = it->path().extension().string();
    if (ext != ".json" && ext != ".csv" && ext != ".png" && ext != ".mp4" && ext != ".avi") continue;
    std::error_code e2;  // a link to a file not yet there is written through: fine
    if (fs::exists(it->path(), e2) && !fs::is_regular_file(it->path(), e2))
      throw UsageError(what + ": " + core::printable_for_message(it->path().string()) +
                       " is not a file, where an output file may go; remove it or choose another folder");
  }
}

void check_output_file(const std::string& path, std::string_view option, std::string_view what_file) {
  require_path(path, option, what_file);
  namespace fs = std::filesystem;
  const std::string what = std::string(option) + " " + core::printable_for_message(path);
  if (path.back() == '/') throw UsageError(what + ": ends with '/'; expected " + std::string(what_file) + ", not a folder");
  const fs::path absolute = resolved(path, what);
  std::error_code ec;
  if (!fs::exists(absolute, ec)) return require_writable_parent(absolute, what);
  if (!fs::is_regular_file(absolute, ec))
    throw UsageError(what + ": exists and is not a file; expected " + std::string(what_file));
  if (::access(absolute.c_str(), W_OK) != 0 && ::access(absolute.parent_path().c_str(), W_OK | X_OK) != 0)
    throw UsageError(what + ": this user cannot replace it");
}

void make_output_dir(const std::string& dir, std::string_view option) {
  check_output_dir(dir, option);
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!ec && !fs::is_directory(dir, ec)) ec = std::make_error_code(std::errc::not_a_directory);
  if (ec)
    throw UsageError(std::string(option) + ": cannot make the output directory '" +
                     core::printable_for_message(dir) + "': " + ec.message());
}

void refuse_given(const CLI::Option* option, std::string_view applies) {
  if (option->count() > 0) throw UsageError(option->get_name() + ": applies " + std::string(applies));
}

void refuse_empty_values(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0) continue;
    for (const std::string& v : opt->results()) {
      if (!v.empty()) continue;
      const std::string name = opt->get_name();
      throw UsageError((name.empty() ? std::string("an argument of ") + app.get_name() : name) +
                       ": expected a value, got an empty one");
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) refuse_empty_values(*sub);
}

CLI::Validator range_check(double lo, double hi, std::string_view unit) {
  std::ostringstream name;
  name << "NUMBER " << lo << ".." << hi << (unit.empty() ? "" : " ") << unit;
  return CLI::Validator(
      [lo, hi, unit = std::string(unit)](std::string& s) -> std::string {
        double x = std::nan("");
        const char* end = s.data() + s.size();
        auto [ptr, ec] = std::from_chars(s.data(), end, x);
        if (ec == std::errc() && ptr == end && in_range(x, lo, hi)) return {};
        std::ostringstream os;
        os << "expected " << lo << " to " << hi << (unit.empty() ? "" : " ") << unit << ", got '" << s << "'";
        return os.str();
      },
      name.str());
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
