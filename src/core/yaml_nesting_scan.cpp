// find_excess_nesting: how deep maps and sequences nest, estimated from the raw YAML text.
#include <cstddef>
#include <vector>

#include "yaml_checks.hpp"

namespace spidar::core {
namespace {

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

/// An open block collection: the column of its entries, and whether it is a sequence.
struct BlockLevel {
  std::size_t col;
  bool seq;
};

/// Opens the block collection whose entries start at `col` (after deeper ones were closed).
/// A sequence may sit at the same column as the keys of the map that holds it.
void open_block_level(std::vector<BlockLevel>& levels, std::size_t col, bool seq) {
  if (!levels.empty() && levels.back().col == col) {
    if (levels.back().seq == seq) return;
    if (!seq) {
      levels.pop_back();  // the sequence at its map's column ended; back in that map
      if (!levels.empty() && levels.back().col == col) return;
    }
  }
  levels.push_back({col, seq});
}

class NestingScan {
 public:
  NestingScan(std::string_view text, int max_depth) : text_(text), max_depth_(max_depth) {}

  int run() {
    std::size_t begin = 0;
    for (int line = 1;; ++line) {
      std::size_t end = text_.find('\n', begin);
      if (end == std::string_view::npos) end = text_.size();
      if (line_too_deep(text_.substr(begin, end - begin))) return line;
      if (end == text_.size()) return 0;
      begin = end + 1;
    }
  }

 private:
  enum class Quote { kNone, kSingle, kDouble };

  int line_depth() const {
    return static_cast<int>(levels_.size()) + indicators_ - (first_is_indicator_ ? 1 : 0) +
           (compact_map_ ? 1 : 0);
  }

  /// Scans one line; true if the nesting went beyond the limit on it.
  bool line_too_deep(std::string_view s) {
    std::size_t indent = 0;
    while (indent < s.size() && s[indent] == ' ') ++indent;
    std::size_t first = indent;
    while (first < s.size() && is_blank(s[first])) ++first;
    const bool blank = first == s.size();

    if (quote_ == Quote::kNone && block_scalar_) {
      if (blank || indent > block_scalar_indent_) return false;  // block scalar content
      block_scalar_ = false;
    }
    indicators_ = 0;
    first_is_indicator_ = false;
    compact_map_ = false;
    line_level_open_ = false;
    indent_ = indent;
    const bool block_line = quote_ == Quote::kNone && flow_ == 0;
    std::size_t pos = 0;
    if (block_line) {
      if (blank || s[first] == '#') return false;
      while (!levels_.empty() && levels_.back().col > indent) levels_.pop_back();
      const auto rest = s.substr(indent);
      if (indent == 0 && (rest.starts_with("---") || rest.starts_with("...")) &&
          (rest.size() == 3 || is_blank(rest[3]))) {
        levels_.clear();  // a new document
        pos = 3;
      } else {
        pos = indent;
      }
      node_start_ = true;
    }
    if (scan(s, pos)) return true;
    return flow_ == 0 && line_depth() > max_depth_;
  }

  /// Scans characters from `pos`; true if a flow collection opened beyond the limit.
  bool scan(std::string_view s, std::size_t pos) {
    for (; pos < s.size(); ++pos) {
      const char c = s[pos];
      if (quote_ == Quote::kSingle) {
        if (c == '\'') {
          if (pos + 1 < s.size() && s[pos + 1] == '\'') {
            ++pos;  // '' is a quote inside the string
          } else {
            quote_ = Quote::kNone;
            node_start_ = false;
          }
        }
        continue;
      }
      if (quote_ == Quote::kDouble) {
        if (c == '\\') {
          ++pos;
        } else if (c == '"') {
          quote_ = Quote::kNone;
          node_start_ = false;
        }
        continue;
      }
      if (is_blank(c)) continue;
      const bool after_blank = pos == 0 || is_blank(s[pos - 1]);
      const bool before_blank = pos + 1 == s.size() || is_blank(s[pos + 1]);
      if (c == '#' && after_blank) return false;  // comment to the end of the line
      if (node_start_ && (c == '\'' || c == '"')) {
        quote_ = c == '\'' ? Quote::kSingle : Quote::kDouble;
        continue;
      }
      if ((c == '[' || c == '{') && (flow_ > 0 || node_start_)) {
        if (flow_ == 0) block_depth_ = line_depth();
        ++flow_;
        node_start_ = true;
        if (block_depth_ + flow_ > max_depth_) return true;
        continue;
      }
      if ((c == ']' || c == '}') && flow_ > 0) {
        --flow_;
        node_start_ = false;
        continue;
      }
      if (flow_ > 0) {
        if (c == ',' || c == ':') {
          node_start_ = true;
          continue;
        }
        if (c == '?' && node_start_ && before_blank) continue;
      } else {
        if ((c == '-' || c == '?') && node_start_ && before_blank) {
          if (pos == indent_) {
            open_block_level(levels_, indent_, c == '-');
            first_is_indicator_ = true;
            line_level_open_ = true;
          }
          ++indicators_;
          compact_map_ = false;
          continue;
        }
        if (c == ':' && before_blank) {
          if (indicators_ > 0) {
            compact_map_ = true;
          } else if (!line_level_open_) {
            open_block_level(levels_, indent_, false);
            line_level_open_ = true;
          }
          node_start_ = true;
          continue;
        }
        if ((c == '|' || c == '>') && node_start_) {
          block_scalar_ = true;
          block_scalar_indent_ = indent_;
          return false;
        }
      }
      if ((c == '&' || c == '!') && node_start_) {
        // An anchor or a tag: the node itself starts after it.
        while (pos + 1 < s.size() && !is_blank(s[pos + 1]) && s[pos + 1] != '[' &&
               s[pos + 1] != '{' && s[pos + 1] != ']' && s[pos + 1] != '}' && s[pos + 1] != ',') {
          ++pos;
        }
        continue;
      }
      node_start_ = false;
    }
    return false;
  }

  std::string_view text_;
  int max_depth_;
  std::vector<BlockLevel> levels_;  ///< open block collections, outermost first
  Quote quote_ = Quote::kNone;      ///< inside a quoted scalar (may span lines)
  int flow_ = 0;                    ///< open flow collections `[` `{`
  int block_depth_ = 0;             ///< block depth of the line that opened the flow context
  bool block_scalar_ = false;       ///< inside the content of a `|` or `>` scalar
  std::size_t block_scalar_indent_ = 0;
  bool node_start_ = true;  ///< the next non-blank character starts a node
  // Per block line:
  std::size_t indent_ = 0;
  int indicators_ = 0;               ///< `- ` and `? ` entries on this line
  bool first_is_indicator_ = false;  ///< the line starts with one (its level is in levels_)
  bool compact_map_ = false;         ///< `key: ` after an indicator: a map inside the entry
  bool line_level_open_ = false;     ///< this line's own block level is already counted
};

}  // namespace

int find_excess_nesting(std::string_view text, int max_depth) {
  return NestingScan(text, max_depth).run();
}

}  // namespace spidar::core
