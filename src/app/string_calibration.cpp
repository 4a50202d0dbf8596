#include "string_calibration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_support.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/core/config.hpp"
#include "spidar/strings/encoder.hpp"
#include "spidar/strings/position.hpp"

namespace spidar::app {

std::vector<std::int64_t> finger_counts(const strings::DeviceConfig& config, int finger,
                                        const device::EncoderReading& reading) {
  int first = 0;
  for (int f = 0; f < finger; ++f) first += config.fingers[f].geometry.n;
  const int n = config.fingers[finger].geometry.n;
  std::vector<std::int64_t> counts(n);
  for (int i = 0; i < n; ++i) counts[i] = reading.counts[first + i];
  return counts;
}

std::optional<Vec3> fingertip_from_counts(const strings::FingerConfig& finger,
                                          std::span<const strings::EncoderChannel> channels,
                                          std::span<const std::int64_t> counts) {
  const int n = finger.geometry.n;
  std::vector<double> lengths(n);
  for (int i = 0; i < n; ++i) lengths[i] = strings::counts_to_length(channels[i], counts[i]);
  const auto est = strings::solve_position(finger.geometry, lengths);
  if (!est) return std::nullopt;
  return est->p_WF;
}

StabilityCheck::StabilityCheck(const strings::FingerConfig& finger, const Vec3& p_W_target,
                               StabilityParams params)
    : finger_(finger), target_(p_W_target), p_(params) {}

void StabilityCheck::update(double t_s, std::span<const std::int64_t> counts) {
  const int n = finger_.geometry.n;
  window_.emplace_back(t_s, std::vector<std::int64_t>(counts.begin(), counts.begin() + n));
  while (!window_.empty() && window_.front().first < t_s - p_.hold_s) window_.pop_front();
  // Spread of each string over the window, in metres.
  spread_m_ = 0;
  for (int i = 0; i < n; ++i) {
    std::int64_t lo = window_.front().second[i], hi = lo;
    for (const auto& [t, c] : window_) {
      lo = std::min(lo, c[i]);
      hi = std::max(hi, c[i]);
    }
    spread_m_ = std::max(spread_m_, static_cast<double>(hi - lo) * finger_.channels[i].metres_per_count);
  }
  // Where the present calibration puts the fingertip.
  const auto p_W = fingertip_from_counts(finger_, counts);
  distance_m_ = p_W ? (*p_W - target_).norm() : 1e9;
  // Held still: the window covers hold_s and nothing moved more than the tolerance in it.
  if (spread_m_ > p_.tolerance_m || distance_m_ > p_.near_m || window_.size() == 1) {
    window_.clear();
    window_.emplace_back(t_s, std::vector<std::int64_t>(counts.begin(), counts.begin() + n));
    still_since_ = t_s;
    held_s_ = 0;
    return;
  }
  held_s_ = t_s - still_since_;
  ready_ = ready_ || held_s_ >= p_.hold_s;
}

std::vector<std::int64_t> StabilityCheck::sample() const {
  const int n = finger_.geometry.n;
  std::vector<std::int64_t> out(n, 0);
  if (window_.empty()) return out;
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (const auto& [t, c] : window_) sum += static_cast<double>(c[i]);
    out[i] = std::llround(sum / static_cast<double>(window_.size()));
  }
  return out;
}

CalibrationUser::CalibrationUser(const strings::DeviceConfig& config, double approach_s)
    : rest_(device::rest_points(config)), hover_(device::hovering_hands(rest_)), approach_s_(approach_s) {}

void CalibrationUser::activate(int finger, const Vec3& p_W_target, double t_s) {
  // Start from wherever the finger is meant to be now.
  std::vector<Vec3> now(rest_.size());
  goals(t_s, now);
  finger_ = finger;
  from_ = finger >= 0 && finger < static_cast<int>(now.size()) ? now[finger] : Vec3::Zero();
  target_ = p_W_target;
  t_active_ = t_s;
}

void CalibrationUser::goals(double t_s, std::span<Vec3> p_W_goal) {
  hover_(t_s, p_W_goal);
  if (finger_ < 0 || finger_ >= static_cast<int>(p_W_goal.size())) return;
  const double u = std::clamp((t_s - t_active_) / approach_s_, 0.0, 1.0);
  const double s = u * u * (3 - 2 * u);  // smoothstep: at rest at both ends
  p_W_goal[finger_] = from_ + s * (target_ - from_);
}

namespace {

int indent_of(const std::string& line) {
  const auto p = line.find_first_not_of(' ');
  return p == std::string::npos ? -1 : static_cast<int>(p);
}

std::string list_line(int indent, const std::string& key, const std::vector<std::string>& values,
                      const std::string& comment) {
  std::string s(static_cast<std::size_t>(indent), ' ');
  s += key + ": [";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? ", " : "") + values[i];
  s += "]";
  if (!comment.empty()) s += "  # " + comment;
  return s;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

std::string with_finger_channels(const std::string& yaml, const std::string& source,
                                 const std::string& finger,
                                 std::span<const strings::EncoderChannel> channels, bool full,
                                 const std::string& note) {
  std::vector<std::string> lines;
  {
    std::stringstream ss(yaml);
    std::string l;
    while (std::getline(ss, l)) lines.push_back(l);
  }
  // The finger's block: "- name: <finger>" and the lines indented deeper than its keys' column.
  std::size_t start = lines.size();
  int key_indent = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const int ind = indent_of(lines[i]);
    if (ind < 0) continue;
    std::string rest = lines[i].substr(static_cast<std::size_t>(ind));
    if (rest.rfind("- name:", 0) != 0) continue;
    std::string name = rest.substr(7);
    if (const auto hash = name.find('#'); hash != std::string::npos) name = name.substr(0, hash);
    name.erase(0, name.find_first_not_of(" \"'"));
    name.erase(name.find_last_not_of(" \"'") + 1);
    if (name == finger) {
      start = i;
      key_indent = ind + 2;
      break;
    }
  }
  if (start == lines.size())
    throw UsageError(source + ": no finger '" + finger + "' (a line '- name: " + finger + "') to write to");
  auto block_end = [&] {
    std::size_t j = start + 1;
    for (; j < lines.size(); ++j) {
      const int ind = indent_of(lines[j]);
      if (ind < 0) continue;
      if (lines[j][static_cast<std::size_t>(ind)] == '#') continue;
      if (ind < key_indent) break;
    }
    return j;
  };
  std::vector<std::string> keys = {"length_at_zero"};
  if (full) keys = {"signs", "metres_per_count", "length_at_zero"};
  for (const std::string& key : keys) {
    const std::size_t end = block_end();
    for (std::size_t j = start + 1; j < end; ++j) {
      if (indent_of(lines[j]) != key_indent || lines[j].compare(key_indent, key.size() + 1, key + ":") != 0) continue;
      std::size_t k = j + 1;  // a block list continues on deeper-indented lines
      while (k < end && (indent_of(lines[k]) > key_indent || indent_of(lines[k]) < 0)) ++k;
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(j), lines.begin() + static_cast<std::ptrdiff_t>(k));
      break;
    }
  }
  std::vector<std::string> l0, mpc, signs;
  for (const auto& c : channels) {
    l0.push_back(num(c.length_at_zero));
    mpc.push_back(num(c.metres_per_count));
    signs.push_back(c.sign > 0 ? "1" : "-1");
  }
  std::vector<std::string> insert;
  if (full) {
    insert.push_back(list_line(key_indent, "signs", signs, ""));
    insert.push_back(list_line(key_indent, "metres_per_count", mpc, "m/count"));
  }
  insert.push_back(list_line(key_indent, "length_at_zero", l0, "m; " + note));
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(start + 1), insert.begin(), insert.end());
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

std::string keep_previous_version(const std::string& path) {
  namespace fs = std::filesystem;
  if (!fs::exists(path)) return "";
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  localtime_r(&now, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &tm);
  std::string backup = path + ".bak-" + stamp;
  for (int k = 2; fs::exists(backup); ++k) backup = path + ".bak-" + stamp + "-" + std::to_string(k);
  std::error_code ec;
  fs::copy_file(path, backup, ec);
  if (ec) throw UsageError(path + ": cannot keep the previous version as " + backup + ": " + ec.message());
  return backup;
}

std::string write_config_with_backup(const std::string& path, const std::string& text) {
  (void)strings::parse_device_config(core::ConfigNode::Parse(text, path));  // throws ConfigError
  const std::string backup = keep_previous_version(path);
  // Whole or not at all, and through a symbolic link to the file it names (the link stays).
  core::write_file_atomic(path, text);
  return backup;
}

}  // namespace spidar::app
