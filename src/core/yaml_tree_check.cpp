// check_yaml_tree: nesting depth, node count, key shapes and duplicate keys of a parsed document.
#include <yaml-cpp/yaml.h>

#include <string>
#include <unordered_map>

#include "spidar/core/config.hpp"
#include "yaml_checks.hpp"

namespace spidar::core {
namespace {

int line_of(const YAML::Node& n) {
  const auto mark = n.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

class TreeCheck {
 public:
  TreeCheck(const std::string& file, const YamlLimits& limits) : file_(file), limits_(limits) {}

  /// Checks `n`, found at `path`, whose parent collections are `depth` deep. The recursion is at
  /// most `limits.max_depth` deep: it stops with an error before going further.
  void visit(const YAML::Node& n, int depth, const std::string& path) {
    if (++nodes_ > limits_.max_nodes) {
      fail(n, path,
           "expected at most " + std::to_string(limits_.max_nodes) +
               " values in the document (an aliased value counts each time it is used)");
    }
    if (!n.IsMap() && !n.IsSequence()) return;
    if (depth + 1 > limits_.max_depth) {
      fail(n, path,
           "expected at most " + std::to_string(limits_.max_depth) +
               " levels of nested maps and sequences");
    }
    if (n.IsSequence()) {
      std::size_t i = 0;
      for (const auto& item : n) visit(item, depth + 1, child_index_path(path, i++));
      return;
    }
    std::unordered_map<std::string, int> first_line;
    for (const auto& kv : n) {
      const YAML::Node& key = kv.first;
      if (key.IsMap() || key.IsSequence()) {
        fail(key, path,
             "expected a plain key, got a " + std::string(key.IsMap() ? "map" : "sequence") +
                 " as a key");
      }
      const std::string name = key.Scalar();
      const int line = line_of(key);
      const auto [it, inserted] = first_line.emplace(name, line);
      if (!inserted) {
        fail(key, path,
             "duplicate key " + quoted_for_message(name) + " (first at line " +
                 std::to_string(it->second) + ")");
      }
      visit(kv.second, depth + 1, child_key_path(path, key_for_path(name, line)));
    }
  }

 private:
  [[noreturn]] void fail(const YAML::Node& at, const std::string& path,
                         const std::string& expectation) const {
    throw ConfigError(file_, line_of(at), path, expectation);
  }

  const std::string& file_;
  const YamlLimits& limits_;
  std::size_t nodes_ = 0;
};

}  // namespace

void check_yaml_tree(const YAML::Node& root, const std::string& file, const YamlLimits& limits) {
  TreeCheck(file, limits).visit(root, 0, "");
}

}  // namespace spidar::core
