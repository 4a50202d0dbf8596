#pragma once
/// Reading YAML configuration into typed structs, with errors that say where and what:
///   `configs/spidar8.yaml:14: fingers[3].fulcrums[1]: expected 3 numbers, got 2`
///
/// A `ConfigNode` is a position in a parsed document: the file name, the key path from the
/// root and the line it came from. Accessors check the type and throw `ConfigError` with that
/// location. Parsers of module configs take a `ConfigNode`, so they stay free of file I/O.
///
/// Loading is strict and bounded, since a config path or its text may come from anyone:
///   - `LoadFile` reads only regular files of at most `kMaxConfigFileBytes` (see
///     `read_file_bounded`): no directories, FIFOs or devices, no NUL in the path.
///   - `Parse` refuses nesting of maps/sequences deeper than `kMaxConfigNesting` (checked on the
///     raw text before yaml-cpp parses it, and again on the tree), more than `kMaxConfigNodes`
///     values (aliases expanded), keys that are maps or sequences, and duplicate keys in a map.
///   - Every failure is a `ConfigError` `file:line: key: expectation`; no yaml-cpp exception
///     escapes, and messages do not quote the file's content except short plain words (a bad
///     number such as 'abc', a key name), so a file that is not a config is not echoed.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"

namespace YAML {
class Node;
}

namespace spidar::core {

/// A configuration error with its location. `what()` is the full one-line message.
class ConfigError : public SpidarError {
 public:
  ConfigError(std::string file, int line, std::string key, std::string expectation);
  const std::string& file() const { return file_; }
  int line() const { return line_; }  ///< 1-based; 0 when unknown
  const std::string& key() const { return key_; }
  const std::string& expectation() const { return expectation_; }

 private:
  std::string file_;
  int line_;
  std::string key_;
  std::string expectation_;
};

/// The largest config file `LoadFile` reads, in bytes: 1 MiB. Our configs are a few KiB; yaml-cpp
/// needs about 230 bytes of memory per byte of a dense list such as `[0,0,...]` (a 1 MiB one took
/// 243 MB and 2.2 s to load here), so this also bounds what a hostile file can cost.
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{1} << 20;
/// The deepest nesting of maps and sequences a config may have; the top-level map is level 1.
inline constexpr int kMaxConfigNesting = 64;
/// The most values a config may hold, counting an aliased value each time it is used (bounds
/// "billion laughs" documents, whose aliases expand exponentially).
inline constexpr std::size_t kMaxConfigNodes = 1'000'000;

class ConfigNode {
 public:
  /// Reads (at most `max_bytes`, see `read_file_bounded`) and parses a YAML file. Throws
  /// ConfigError (with the file name) if it is missing, not a regular file, too large, or does
  /// not pass `Parse`.
  static ConfigNode LoadFile(const std::string& path, std::size_t max_bytes = kMaxConfigFileBytes);
  /// Parses YAML text; `name` stands for the file in messages. Throws ConfigError if the text is
  /// malformed, nests deeper than `kMaxConfigNesting`, holds more than `kMaxConfigNodes` values,
  /// repeats a key in a map (`duplicate key 'device' (first at line 3)`), has a map or sequence
  /// as a key, or is not a map at the top level.
  static ConfigNode Parse(std::string_view text, const std::string& name);

  const std::string& file() const { return *file_; }
  const std::string& path() const { return path_; }  ///< e.g. `fingers[3].fulcrums[1]`
  int line() const;                                   ///< 1-based line of this node

  bool is_map() const;
  bool is_sequence() const;
  bool is_null() const;

  bool has(std::string_view key) const;
  /// A required key of a map. Missing key → ConfigError naming the key.
  ConfigNode operator[](std::string_view key) const;
  /// An optional key of a map.
  std::optional<ConfigNode> find(std::string_view key) const;
  /// Keys of a map in document order.
  std::vector<std::string> keys() const;
  /// Rejects keys not in `allowed` (catches typos such as `fulcrum:`). A null node (an empty
  /// value) has no keys; a scalar or a sequence is an error.
  void expect_keys(std::initializer_list<std::string_view> allowed) const;

  /// Number of entries of a sequence (error if not a sequence).
  std::size_t size() const;
  /// Entry i of a sequence.
  ConfigNode at(std::size_t i) const;

  double as_double() const;  ///< finite number
  std::int64_t as_int() const;
  bool as_bool() const;
  std::string as_string() const;
  Vec3 as_vec3() const;  ///< a sequence of exactly 3 finite numbers
  std::vector<double> as_doubles() const;

  /// Convenience for optional scalars.
  double get_double(std::string_view key, double fallback) const;
  std::int64_t get_int(std::string_view key, std::int64_t fallback) const;

  /// Throws ConfigError at this node: `file:line: path: expectation`.
  [[noreturn]] void fail(std::string_view expectation) const;

 private:
  ConfigNode(std::shared_ptr<const YAML::Node> node, std::shared_ptr<const std::string> file,
             std::string path);
  /// This node's scalar text; fails with `expected` if the node is not a scalar.
  const std::string& scalar(std::string_view expected) const;
  std::string child_path(std::string_view key) const;
  std::string child_path(std::size_t i) const;

  std::shared_ptr<const YAML::Node> node_;
  std::shared_ptr<const std::string> file_;
  std::string path_;
};

/// Checks a number against [lo, hi] and fails at `node` with the range if outside.
double require_in_range(const ConfigNode& node, double value, double lo, double hi,
                        std::string_view unit);

/// `node` as a whole number in [lo, hi]; fails at `node` with "expected lo..hi, got N" otherwise
/// (a number beyond 64 bits, or with a fraction, fails as as_int() fails).
std::int64_t require_int_in_range(const ConfigNode& node, std::int64_t lo, std::int64_t hi);

/// `node` as text with something besides blanks (a name); fails at `node` with "expected a
/// non-blank `what`, got '...'" otherwise.
std::string require_non_blank(const ConfigNode& node, std::string_view what);

/// A number as an error message shows it: `significant` digits, no trailing zeros (300, 0.15,
/// 1e-05, 3e+09), so that a message quotes what was written rather than 300.000000.
std::string number_for_message(double v, int significant = 6);

/// Fails with a validate() message of the form `prefix` + "key: expectation" at that key's own
/// node when the map `node` has it (file:line of the key, `map.key: expectation`), else at `node`
/// with the whole message.
[[noreturn]] void fail_at_named_key(const ConfigNode& node, std::string_view message, std::string_view prefix);

}  // namespace spidar::core
