#include "spidar/core/config.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>
#include <sstream>

#include "spidar/core/file_read.hpp"
#include "spidar/core/utf8.hpp"
#include "yaml_checks.hpp"

namespace spidar::core {
namespace {

std::string format_location(const std::string& file, int line, const std::string& key) {
  std::ostringstream os;
  os << file;
  if (line > 0) os << ':' << line;
  os << ':';
  if (!key.empty()) os << ' ' << key << ':';
  return os.str();
}

const char* type_name(const YAML::Node& n) {
  YAML::NodeType::value type = YAML::NodeType::Undefined;
  try {
    type = n.Type();
  } catch (const YAML::Exception&) {
  }
  switch (type) {
    case YAML::NodeType::Null:
      return "nothing";
    case YAML::NodeType::Scalar:
      return "a scalar";
    case YAML::NodeType::Sequence:
      return "a sequence";
    case YAML::NodeType::Map:
      return "a map";
    default:
      return "an undefined node";
  }
}

/// Runs `body` (an accessor's work on yaml-cpp nodes) so that no yaml-cpp exception leaves it:
/// any is reported at `node` as `expectation`. ConfigError and std::bad_alloc pass through.
template <typename Body>
decltype(auto) guarded(const ConfigNode& node, std::string_view expectation, Body&& body) {
  try {
    return body();
  } catch (const SpidarError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception&) {
    node.fail(expectation);
  }
}

}  // namespace

ConfigError::ConfigError(std::string file, int line, std::string key, std::string expectation)
    // One line whatever the key or file name holds: control characters (a key may hold any byte)
    // are written as \xNN.
    : SpidarError(printable_for_message(format_location(file, line, key) + ' ' + expectation)),
      file_(std::move(file)),
      line_(line),
      key_(std::move(key)),
      expectation_(std::move(expectation)) {}

ConfigNode::ConfigNode(std::shared_ptr<const YAML::Node> node,
                       std::shared_ptr<const std::string> file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

ConfigNode ConfigNode::LoadFile(const std::string& path, std::size_t max_bytes) {
  std::string text;
  try {
    text = read_file_bounded(path, max_bytes, "a config file");
  } catch (const FileError& e) {
    throw ConfigError(printable_for_message(path), 0, "", e.reason());
  }
  return Parse(text, printable_for_message(path));
}

ConfigNode ConfigNode::Parse(std::string_view text, const std::string& name) {
  auto file = std::make_shared<const std::string>(name);
  const YamlLimits limits{kMaxConfigNesting, kMaxConfigNodes};
  const std::string too_deep = "expected at most " + std::to_string(limits.max_depth) +
                               " levels of nested maps and sequences";
  if (const int line = find_excess_nesting(text, limits.max_depth); line > 0) {
    throw ConfigError(name, line, "", too_deep);
  }
  std::shared_ptr<const YAML::Node> node;
  try {
    node = std::make_shared<const YAML::Node>(YAML::Load(std::string(text)));
    check_yaml_tree(*node, name, limits);
  } catch (const SpidarError&) {
    throw;
  } catch (const YAML::DeepRecursion& e) {
    throw ConfigError(name, e.mark.is_null() ? 0 : e.mark.line + 1, "", too_deep);
  } catch (const YAML::Exception& e) {
    std::string what = "malformed YAML: " + describe_parser_error(e);
    if (!e.mark.is_null()) what += " (column " + std::to_string(e.mark.column + 1) + ")";
    throw ConfigError(name, e.mark.is_null() ? 0 : e.mark.line + 1, "", what);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception&) {
    throw ConfigError(name, 0, "", "malformed YAML: the YAML parser failed");
  }
  ConfigNode root(node, file, "");
  if (!node->IsMap()) root.fail("expected a YAML map at the top level");
  return root;
}

int ConfigNode::line() const {
  try {
    const auto mark = node_->Mark();
    return mark.is_null() ? 0 : mark.line + 1;
  } catch (const YAML::Exception&) {
    return 0;
  }
}

bool ConfigNode::is_map() const {
  return guarded(*this, "expected a valid node", [&] { return node_->IsMap(); });
}
bool ConfigNode::is_sequence() const {
  return guarded(*this, "expected a valid node", [&] { return node_->IsSequence(); });
}
bool ConfigNode::is_null() const {
  return guarded(*this, "expected a valid node",
                 [&] { return !node_->IsDefined() || node_->IsNull(); });
}

std::string ConfigNode::child_path(std::string_view key) const {
  return child_key_path(path_, key);
}

std::string ConfigNode::child_path(std::size_t i) const {
  return child_index_path(path_, i);
}

bool ConfigNode::has(std::string_view key) const {
  return guarded(*this, "expected a map",
                 [&] { return node_->IsMap() && (*node_)[std::string(key)].IsDefined(); });
}

std::optional<ConfigNode> ConfigNode::find(std::string_view key) const {
  if (!is_map()) fail(std::string("expected a map, got ") + type_name(*node_));
  return guarded(*this, "expected a map", [&]() -> std::optional<ConfigNode> {
    YAML::Node child = (*node_)[std::string(key)];
    if (!child.IsDefined()) return std::nullopt;
    return ConfigNode(std::make_shared<const YAML::Node>(child), file_, child_path(key));
  });
}

ConfigNode ConfigNode::operator[](std::string_view key) const {
  auto child = find(key);
  if (!child) fail("missing required key '" + std::string(key) + "'");
  return *child;
}

std::vector<std::string> ConfigNode::keys() const {
  if (!is_map()) fail(std::string("expected a map, got ") + type_name(*node_));
  return guarded(*this, "expected a map with plain keys", [&] {
    std::vector<std::string> out;
    for (const auto& kv : *node_) out.push_back(kv.first.Scalar());
    return out;
  });
}

void ConfigNode::expect_keys(std::initializer_list<std::string_view> allowed) const {
  if (is_null()) return;
  if (!is_map()) fail(std::string("expected a map, got ") + type_name(*node_));
  guarded(*this, "expected a map with plain keys", [&] {
    for (const auto& kv : *node_) {
      const std::string& key = kv.first.Scalar();
      bool known = false;
      for (auto a : allowed) known = known || (a == key);
      if (known) continue;
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      const auto mark = kv.first.Mark();
      const int key_line = mark.is_null() ? line() : mark.line + 1;
      throw ConfigError(*file_, key_line, child_path(key_for_path(key, key_line)),
                        "unknown key; expected one of: " + list);
    }
  });
}

std::size_t ConfigNode::size() const {
  if (!is_sequence()) fail(std::string("expected a sequence, got ") + type_name(*node_));
  return guarded(*this, "expected a sequence", [&] { return node_->size(); });
}

ConfigNode ConfigNode::at(std::size_t i) const {
  if (i >= size()) fail("index " + std::to_string(i) + " out of range");
  return guarded(*this, "expected a sequence", [&] {
    return ConfigNode(std::make_shared<const YAML::Node>((*node_)[i]), file_, child_path(i));
  });
}

const std::string& ConfigNode::scalar(std::string_view expected) const {
  const bool scalar = guarded(*this, expected, [&] { return node_->IsScalar(); });
  if (!scalar) fail(std::string(expected) + ", got " + type_name(*node_));
  return guarded(*this, expected, [&]() -> const std::string& { return node_->Scalar(); });
}

double ConfigNode::as_double() const {
  const std::string& text = scalar("expected a number");
  double v = 0.0;
  try {
    v = node_->as<double>();
  } catch (const std::exception&) {
    fail("expected a number, got " + quoted_for_message(text));
  }
  if (!std::isfinite(v)) fail("expected a finite number, got " + quoted_for_message(text));
  return v;
}

std::int64_t ConfigNode::as_int() const {
  const std::string& text = scalar("expected an integer");
  try {
    return node_->as<std::int64_t>();
  } catch (const std::exception&) {
    fail("expected an integer, got " + quoted_for_message(text));
  }
}

bool ConfigNode::as_bool() const {
  const std::string& text = scalar("expected true or false");
  try {
    return node_->as<bool>();
  } catch (const std::exception&) {
    fail("expected true or false, got " + quoted_for_message(text));
  }
}

std::string ConfigNode::as_string() const {
  const std::string& text = scalar("expected a string");
  if (const auto bad = first_invalid_utf8(text)) {
    char byte[8];
    std::snprintf(byte, sizeof byte, "0x%02X", static_cast<unsigned>(static_cast<unsigned char>(text[*bad])));
    fail("expected UTF-8 text, got byte " + std::string(byte) + " at offset " + std::to_string(*bad));
  }
  return text;
}

std::vector<double> ConfigNode::as_doubles() const {
  if (!is_sequence()) {
    fail(std::string("expected a sequence of numbers, got ") + type_name(*node_));
  }
  std::vector<double> out;
  const std::size_t n = size();
  for (std::size_t i = 0; i < n; ++i) out.push_back(at(i).as_double());
  return out;
}

Vec3 ConfigNode::as_vec3() const {
  if (!is_sequence()) fail(std::string("expected 3 numbers, got ") + type_name(*node_));
  const std::size_t n = size();
  if (n != 3) fail("expected 3 numbers, got " + std::to_string(n));
  return {at(0).as_double(), at(1).as_double(), at(2).as_double()};
}

double ConfigNode::get_double(std::string_view key, double fallback) const {
  auto child = find(key);
  return child ? child->as_double() : fallback;
}

std::int64_t ConfigNode::get_int(std::string_view key, std::int64_t fallback) const {
  auto child = find(key);
  return child ? child->as_int() : fallback;
}

void ConfigNode::fail(std::string_view expectation) const {
  throw ConfigError(*file_, line(), path_, std::string(expectation));
}

double require_in_range(const ConfigNode& node, double value, double lo, double hi,
                        std::string_view unit) {
  if (!(value >= lo && value <= hi)) {
    std::ostringstream os;
    os << "expected a value in [" << lo << ", " << hi << "]" << (unit.empty() ? "" : " ") << unit << ", got "
       << value;
    node.fail(os.str());
  }
  return value;
}

std::int64_t require_int_in_range(const ConfigNode& node, std::int64_t lo, std::int64_t hi) {
  const std::int64_t v = node.as_int();
  if (v < lo || v > hi) node.fail("expected " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + std::to_string(v));
  return v;
}

std::string require_non_blank(const ConfigNode& node, std::string_view what) {
  std::string text = node.as_string();
  if (text.find_first_not_of(" \t") == std::string::npos)
    node.fail("expected a non-blank " + std::string(what) + ", got '" + printable_for_message(text) + "'");
  return text;
}

std::string number_for_message(double v, int significant) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", std::clamp(significant, 1, 17), v);
  return buf;
}

void fail_at_named_key(const ConfigNode& node, std::string_view message, std::string_view prefix) {
  std::string_view rest = message;
  if (rest.substr(0, prefix.size()) == prefix) rest.remove_prefix(prefix.size());
  const std::size_t colon = rest.find(": ");
  if (colon != std::string_view::npos && node.is_map())
    if (const auto child = node.find(rest.substr(0, colon))) child->fail(rest.substr(colon + 2));
  node.fail(message);
}

}  // namespace spidar::core
