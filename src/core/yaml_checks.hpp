#pragma once
/// Checks that make `ConfigNode::Parse` strict and bounded on hostile input (private to core).
///
///   - `find_excess_nesting`: a cheap scan of the raw text, before yaml-cpp sees it, so a
///     document such as `[[[[...` 100000 deep is refused without entering yaml-cpp's recursive
///     parser.
///   - `check_yaml_tree`: the authoritative checks on the parsed tree: nesting depth, duplicate
///     keys, keys that are not scalars, and the number of nodes with aliases expanded.
///   - `describe_parser_error`: a yaml-cpp exception as a message that never quotes the input.
///   - `quoted_for_message`: a scalar or key from the input, quoted only if it is a short plain
///     word, so messages about a file that is not ours do not echo its content.
#include <cstddef>
#include <string>
#include <string_view>

namespace YAML {
class Node;
class Exception;
}  // namespace YAML

namespace spidar::core {

/// Bounds on a parsed YAML document.
struct YamlLimits {
  int max_depth;          ///< nested maps/sequences; the top-level map is depth 1
  std::size_t max_nodes;  ///< nodes in the tree, aliased subtrees counted at every use
};

/// The 1-based line on which the nesting of maps and sequences in `text` first appears to go
/// beyond `max_depth`, or 0 if it does not.
///
/// This is an estimate from the characters alone: flow brackets outside quotes and comments,
/// block indentation levels, and compact `- ` / `? ` entries. It agrees with the parsed tree on
/// ordinary block and flow styles. It is not a proof: text whose quoting it misreads (`a:'b` in
/// a flow sequence is a plain scalar to yaml-cpp, a string opening here) can make it under- or
/// over-count, which is why `check_yaml_tree` checks the parsed tree, and yaml-cpp 0.7 has its
/// own recursion limit (2000, reported as the same nesting error) behind both.
int find_excess_nesting(std::string_view text, int max_depth);

/// Walks the parsed document and throws ConfigError (with `file`, the line and the key path) on
/// the first of: nesting deeper than `limits.max_depth`; more than `limits.max_nodes` nodes; a
/// map key that is a map or a sequence; a key repeated in the same map
/// (`duplicate key 'device' (first at line 3)`).
void check_yaml_tree(const YAML::Node& root, const std::string& file, const YamlLimits& limits);

/// What a yaml-cpp parser exception says, kept only if it is one of yaml-cpp's fixed messages
/// (e.g. `end of sequence flow not found`); messages that would append input text are cut to
/// their fixed part, and anything else becomes `the YAML parser failed`.
std::string describe_parser_error(const YAML::Exception& e);

/// `'text'` if `text` is at most 40 characters of letters, digits, space and `_ . + -`;
/// `an empty text` if empty; otherwise `a text of N characters (not shown)`, so input that is not a
/// plain word (a password hash, binary) is never echoed.
std::string quoted_for_message(std::string_view text);

/// A key as written in a key path: the key itself if it is a plain word (see above), otherwise
/// `<key on line L>`.
std::string key_for_path(std::string_view key, int line);

/// `parent.key`, or `key` at the top level.
std::string child_key_path(const std::string& parent, std::string_view key);
/// `parent[i]`.
std::string child_index_path(const std::string& parent, std::size_t i);

}  // namespace spidar::core
