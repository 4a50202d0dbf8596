#include "spidar/strings/device_config_write.hpp"

#include <cstdio>
#include <sstream>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/core/file_write.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::strings {

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
                                 std::span<const EncoderChannel> channels, bool full,
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
    throw SpidarError(source + ": no finger '" + finger + "' (a line '- name: " + finger +
                      "') to write to");
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
      if (indent_of(lines[j]) != key_indent ||
          lines[j].compare(key_indent, key.size() + 1, key + ":") != 0)
        continue;
      std::size_t k = j + 1;  // a block list continues on deeper-indented lines
      while (k < end && (indent_of(lines[k]) > key_indent || indent_of(lines[k]) < 0)) ++k;
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(j),
                  lines.begin() + static_cast<std::ptrdiff_t>(k));
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
  lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(start + 1), insert.begin(),
               insert.end());
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

std::string write_device_config(const std::string& path, const std::string& text) {
  (void)parse_device_config(core::ConfigNode::Parse(text, path));  // throws ConfigError
  return core::replace_file_keeping_previous(path, text);
}

}  // namespace spidar::strings
