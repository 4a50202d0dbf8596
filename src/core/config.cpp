#include "spidar/core/config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

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
  switch (n.Type()) {
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

}  // namespace

ConfigError::ConfigError(std::string file, int line, std::string key, std::string expectation)
    : SpidarError(format_location(file, line, key) + ' ' + expectation),
      file_(std::move(file)),
      line_(line),
      key_(std::move(key)),
      expectation_(std::move(expectation)) {}

ConfigNode::ConfigNode(std::shared_ptr<const YAML::Node> node,
                       std::shared_ptr<const std::string> file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

ConfigNode ConfigNode::LoadFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, 0, "", "cannot open file (does it exist and is it readable?)");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path);
}

ConfigNode ConfigNode::Parse(std::string_view text, const std::string& name) {
  auto file = std::make_shared<const std::string>(name);
  try {
    auto node = std::make_shared<const YAML::Node>(YAML::Load(std::string(text)));
    ConfigNode root(node, file, "");
    if (!node->IsMap()) root.fail("expected a YAML map at the top level");
    return root;
  } catch (const YAML::Exception& e) {
    throw ConfigError(name, e.mark.is_null() ? 0 : e.mark.line + 1, "",
                      "malformed YAML: " + e.msg);
  }
}

int ConfigNode::line() const {
  const auto mark = node_->Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

bool ConfigNode::is_map() const { return node_->IsMap(); }
bool ConfigNode::is_sequence() const { return node_->IsSequence(); }
bool ConfigNode::is_null() const { return !node_->IsDefined() || node_->IsNull(); }

std::string ConfigNode::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

std::string ConfigNode::child_path(std::size_t i) const {
  return path_ + "[" + std::to_string(i) + "]";
}

bool ConfigNode::has(std::string_view key) const {
  return node_->IsMap() && (*node_)[std::string(key)].IsDefined();
}

std::optional<ConfigNode> ConfigNode::find(std::string_view key) const {
  if (!node_->IsMap()) fail(std::string("expected a map, got ") + type_name(*node_));
  YAML::Node child = (*node_)[std::string(key)];
  if (!child.IsDefined()) return std::nullopt;
  return ConfigNode(std::make_shared<const YAML::Node>(child), file_, child_path(key));
}

ConfigNode ConfigNode::operator[](std::string_view key) const {
  auto child = find(key);
  if (!child) fail("missing required key '" + std::string(key) + "'");
  return *child;
}

std::vector<std::string> ConfigNode::keys() const {
  if (!node_->IsMap()) fail(std::string("expected a map, got ") + type_name(*node_));
  std::vector<std::string> out;
  for (const auto& kv : *node_) out.push_back(kv.first.as<std::string>());
  return out;
}

void ConfigNode::expect_keys(std::initializer_list<std::string_view> allowed) const {
  for (const auto& kv : *node_) {
    const auto key = kv.first.as<std::string>();
    bool known = false;
    for (auto a : allowed) known = known || (a == key);
    if (known) continue;
    std::string list;
    for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    const auto mark = kv.first.Mark();
    throw ConfigError(*file_, mark.is_null() ? line() : mark.line + 1, child_path(key),
                      "unknown key; expected one of: " + list);
  }
}

std::size_t ConfigNode::size() const {
  if (!node_->IsSequence()) fail(std::string("expected a sequence, got ") + type_name(*node_));
  return node_->size();
}

ConfigNode ConfigNode::at(std::size_t i) const {
  if (i >= size()) fail("index " + std::to_string(i) + " out of range");
  return ConfigNode(std::make_shared<const YAML::Node>((*node_)[i]), file_, child_path(i));
}

double ConfigNode::as_double() const {
  if (!node_->IsScalar()) fail(std::string("expected a number, got ") + type_name(*node_));
  double v = 0.0;
  try {
    v = node_->as<double>();
  } catch (const YAML::Exception&) {
    fail("expected a number, got '" + node_->Scalar() + "'");
  }
  if (!std::isfinite(v)) fail("expected a finite number, got '" + node_->Scalar() + "'");
  return v;
}

std::int64_t ConfigNode::as_int() const {
  if (!node_->IsScalar()) fail(std::string("expected an integer, got ") + type_name(*node_));
  try {
    return node_->as<std::int64_t>();
  } catch (const YAML::Exception&) {
    fail("expected an integer, got '" + node_->Scalar() + "'");
  }
}

bool ConfigNode::as_bool() const {
  if (!node_->IsScalar()) fail(std::string("expected true or false, got ") + type_name(*node_));
  try {
    return node_->as<bool>();
  } catch (const YAML::Exception&) {
    fail("expected true or false, got '" + node_->Scalar() + "'");
  }
}

std::string ConfigNode::as_string() const {
  if (!node_->IsScalar()) fail(std::string("expected a string, got ") + type_name(*node_));
  return node_->Scalar();
}

std::vector<double> ConfigNode::as_doubles() const {
  if (!node_->IsSequence()) {
    fail(std::string("expected a sequence of numbers, got ") + type_name(*node_));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < node_->size(); ++i) out.push_back(at(i).as_double());
  return out;
}

Vec3 ConfigNode::as_vec3() const {
  if (!node_->IsSequence()) fail(std::string("expected 3 numbers, got ") + type_name(*node_));
  if (node_->size() != 3) fail("expected 3 numbers, got " + std::to_string(node_->size()));
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
    os << "expected a value in [" << lo << ", " << hi << "] " << unit << ", got " << value;
    node.fail(os.str());
  }
  return value;
}

}  // namespace spidar::core
