// Messages about YAML input that name places and expectations but never quote the input.
#include <yaml-cpp/yaml.h>

#include <array>
#include <string>

#include "yaml_checks.hpp"

namespace spidar::core {
namespace {

constexpr std::size_t kMaxQuotedChars = 40;

bool is_plain_word_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == ' ' ||
         c == '_' || c == '.' || c == '+' || c == '-';
}

bool is_plain_word(std::string_view text) {
  if (text.empty() || text.size() > kMaxQuotedChars) return false;
  for (const char c : text) {
    if (!is_plain_word_char(c)) return false;
  }
  return true;
}

// yaml-cpp's parser messages that are fixed text (nothing from the input is appended). const, not
// constexpr: clang (make fuzz) does not take yaml-cpp's `const char* const` as constant expressions.
const std::array<const char*, 34> kFixedParserMessages = {
    YAML::ErrorMsg::YAML_DIRECTIVE_ARGS,
    YAML::ErrorMsg::YAML_MAJOR_VERSION,
    YAML::ErrorMsg::REPEATED_YAML_DIRECTIVE,
    YAML::ErrorMsg::TAG_DIRECTIVE_ARGS,
    YAML::ErrorMsg::REPEATED_TAG_DIRECTIVE,
    YAML::ErrorMsg::CHAR_IN_TAG_HANDLE,
    YAML::ErrorMsg::TAG_WITH_NO_SUFFIX,
    YAML::ErrorMsg::END_OF_VERBATIM_TAG,
    YAML::ErrorMsg::END_OF_MAP,
    YAML::ErrorMsg::END_OF_MAP_FLOW,
    YAML::ErrorMsg::END_OF_SEQ,
    YAML::ErrorMsg::END_OF_SEQ_FLOW,
    YAML::ErrorMsg::MULTIPLE_TAGS,
    YAML::ErrorMsg::MULTIPLE_ANCHORS,
    YAML::ErrorMsg::MULTIPLE_ALIASES,
    YAML::ErrorMsg::ALIAS_CONTENT,
    YAML::ErrorMsg::INVALID_HEX,
    YAML::ErrorMsg::UNKNOWN_TOKEN,
    YAML::ErrorMsg::DOC_IN_SCALAR,
    YAML::ErrorMsg::EOF_IN_SCALAR,
    YAML::ErrorMsg::CHAR_IN_SCALAR,
    YAML::ErrorMsg::TAB_IN_INDENTATION,
    YAML::ErrorMsg::FLOW_END,
    YAML::ErrorMsg::BLOCK_ENTRY,
    YAML::ErrorMsg::MAP_KEY,
    YAML::ErrorMsg::MAP_VALUE,
    YAML::ErrorMsg::ALIAS_NOT_FOUND,
    YAML::ErrorMsg::ANCHOR_NOT_FOUND,
    YAML::ErrorMsg::CHAR_IN_ALIAS,
    YAML::ErrorMsg::CHAR_IN_ANCHOR,
    YAML::ErrorMsg::ZERO_INDENT_IN_BLOCK,
    YAML::ErrorMsg::CHAR_IN_BLOCK,
    YAML::ErrorMsg::AMBIGUOUS_ANCHOR,
    YAML::ErrorMsg::UNKNOWN_ANCHOR,
};

// Messages that end in `: ` followed by text from the input; only the fixed part is kept.
const std::array<const char*, 3> kPrefixParserMessages = {
    YAML::ErrorMsg::YAML_VERSION,
    YAML::ErrorMsg::INVALID_UNICODE,
    YAML::ErrorMsg::INVALID_ESCAPE,
};

}  // namespace

std::string describe_parser_error(const YAML::Exception& e) {
  for (const char* fixed : kFixedParserMessages) {
    if (e.msg == fixed) return fixed;
  }
  for (const char* prefix : kPrefixParserMessages) {
    const std::string_view p(prefix);
    if (std::string_view(e.msg).starts_with(p)) {
      return std::string(p.substr(0, p.size() - 2));  // without the trailing ": "
    }
  }
  return "the YAML parser failed";
}

std::string quoted_for_message(std::string_view text) {
  if (text.empty()) return "an empty text";
  if (is_plain_word(text)) return "'" + std::string(text) + "'";
  return "a text of " + std::to_string(text.size()) + " characters (not shown)";
}

std::string key_for_path(std::string_view key, int line) {
  if (is_plain_word(key)) return std::string(key);
  return "<key on line " + std::to_string(line) + ">";
}

std::string child_key_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string child_index_path(const std::string& parent, std::size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

}  // namespace spidar::core
