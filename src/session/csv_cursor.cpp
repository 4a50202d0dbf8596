#include "csv_cursor.hpp"

#include <charconv>
#include <cmath>

#include "spidar/core/config.hpp"
#include "spidar/core/file_read.hpp"
#include "spidar/session/recording_reader.hpp"

namespace spidar::session {

CsvCursor::CsvCursor(std::istream& in, std::string name, std::vector<std::string> columns,
                     const std::vector<std::string>& optional)
    : in_(in), name_(std::move(name)), columns_(std::move(columns)) {
  const std::size_t required = columns_.size();
  columns_.insert(columns_.end(), optional.begin(), optional.end());
  const std::string expected = "expected the header row of a version-" + std::to_string(kRecordingVersion) +
                               " recording: " + quote(header_row(columns_));
  if (!read_line()) fail_line("empty file; " + expected, 1);
  ++line_;
  // A UTF-8 byte-order mark (a spreadsheet's "CSV UTF-8") is not part of the first column's name.
  if (line_text_.rfind("\xEF\xBB\xBF", 0) == 0) {
    line_text_.erase(0, 3);
    bom_ = 3;
  }
  split();
  position_.assign(columns_.size(), SIZE_MAX);
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    std::size_t k = 0;
    while (k < columns_.size() && columns_[k] != fields_[i]) ++k;
    if (k == columns_.size())
      throw RecordingError(name_, line_, static_cast<int>(bom_ + starts_[i] + 1),
                           "unknown column " + quote(fields_[i]) + "; " + expected);
    if (position_[k] != SIZE_MAX)
      throw RecordingError(name_, line_, static_cast<int>(bom_ + starts_[i] + 1),
                           "column " + quote(fields_[i]) + " appears twice; " + expected);
    position_[k] = i;
  }
  // The optional group: all of its columns or none (then they are not expected in the rows).
  has_optional_ = false;
  for (std::size_t k = required; k < columns_.size(); ++k) has_optional_ = has_optional_ || position_[k] != SIZE_MAX;
  if (!has_optional_) {
    columns_.resize(required);
    position_.resize(required);
  }
  for (std::size_t k = 0; k < columns_.size(); ++k)
    if (position_[k] == SIZE_MAX) fail_line("no column " + quote(columns_[k]) + "; " + expected);
}

bool CsvCursor::read_line() {
  line_text_.clear();
  line_ended_ = false;
  std::streambuf* sb = in_.rdbuf();
  if (sb == nullptr) return false;
  for (;;) {
    const int c = sb->sbumpc();
    if (c == std::char_traits<char>::eof()) break;
    if (c == '\n') {
      line_ended_ = true;
      break;
    }
    if (line_text_.size() >= kMaxLineBytes)
      fail_line("a line longer than " + std::to_string(kMaxLineBytes) + " bytes (not a recording's CSV?)", line_ + 1);
    line_text_.push_back(static_cast<char>(c));
  }
  if (!line_ended_ && line_text_.empty()) return false;
  if (!line_text_.empty() && line_text_.back() == '\r') line_text_.pop_back();
  return true;
}

void CsvCursor::split() {
  fields_.clear();
  starts_.clear();
  const std::string_view s(line_text_);
  std::size_t at = 0;
  for (;;) {
    const std::size_t comma = s.find(',', at);
    starts_.push_back(at);
    fields_.push_back(s.substr(at, comma == std::string_view::npos ? std::string_view::npos : comma - at));
    if (comma == std::string_view::npos) break;
    at = comma + 1;
  }
}

bool CsvCursor::next() {
  if (!read_line()) return false;
  ++line_;
  if (!line_ended_)
    fail_line("the last row is cut off (no line end): the file was truncated while it was written");
  if (line_text_.empty()) fail_line("an empty line (expected a row of " + std::to_string(columns_.size()) + " fields)");
  split();
  if (fields_.size() < columns_.size())
    throw RecordingError(name_, line_, static_cast<int>(line_text_.size() + 1),
                         std::to_string(fields_.size()) + " fields, expected " + std::to_string(columns_.size()) +
                             " (the row is cut off)");
  if (fields_.size() > columns_.size())
    throw RecordingError(name_, line_, static_cast<int>(starts_[columns_.size()] + 1),
                         std::to_string(fields_.size()) + " fields, expected " + std::to_string(columns_.size()));
  return true;
}

std::size_t CsvCursor::col(std::string_view name) const {
  for (std::size_t k = 0; k < columns_.size(); ++k)
    if (columns_[k] == name) return k;
  throw SpidarError("CsvCursor: no column '" + std::string(name) + "' in the schema");  // a bug, not bad input
}

std::string_view CsvCursor::text(std::size_t c) const { return fields_[position_[c]]; }

std::int64_t CsvCursor::integer(std::size_t c, std::int64_t lo, std::int64_t hi) const {
  const std::string_view s = text(c);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v < lo || v > hi)
    fail(c, "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got " + quote(s));
  return v;
}

std::uint64_t CsvCursor::unsigned_integer(std::size_t c, std::uint64_t hi) const {
  const std::string_view s = text(c);
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v > hi)
    fail(c, "expected an integer from 0 to " + std::to_string(hi) + ", got " + quote(s));
  return v;
}

double CsvCursor::number(std::size_t c) const {
  const std::string_view s = text(c);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
    fail(c, "expected a finite number, got " + quote(s));
  return v;
}

double CsvCursor::number(std::size_t c, double lo, double hi, std::string_view what) const {
  const double v = number(c);
  if (v < lo || v > hi)
    fail(c, "expected " + std::string(what) + " from " + core::number_for_message(lo) + " to " +
                core::number_for_message(hi) + ", got " + quote(text(c)));
  return v;
}

void CsvCursor::fail(std::size_t c, const std::string& what) const {
  throw RecordingError(name_, line_, static_cast<int>(starts_[position_[c]] + 1), columns_[c] + ": " + what);
}

void CsvCursor::fail_line(const std::string& what, int line) const {
  throw RecordingError(name_, line > 0 ? line : line_, 1, what);
}

std::string CsvCursor::quote(std::string_view s) const {
  constexpr std::size_t kMax = 40;
  std::string out = "'" + core::printable_for_message(s.substr(0, kMax));
  if (s.size() > kMax) out += "...";
  return out + "'";
}

}  // namespace spidar::session
