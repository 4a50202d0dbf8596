#pragma once
// Reading a CSV file with a header row, row by row, with every field checked and every error
// naming FILE:LINE:COLUMN and the column's name. Columns are found by name: the header must hold
// exactly the expected names (any order). A '\r' before a line's '\n' is dropped (CRLF files).
#include <cstdint>
#include <istream>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace spidar::session {

class CsvCursor {
 public:
  /// Longest line accepted [bytes]: our widest row is about 1.3 kB.
  static constexpr std::size_t kMaxLineBytes = 64 * 1024;

  /// Reads and checks the header row against `columns` and the `optional` group of columns
  /// (a newer addition: the header has all of them or none). Throws RecordingError.
  CsvCursor(std::istream& in, std::string name, std::vector<std::string> columns,
            const std::vector<std::string>& optional = {});

  /// Reads the next row; false at the end of the file. Throws RecordingError for an empty line, a
  /// row with too few or too many fields, or a last row cut off (no line end).
  bool next();

  /// Index of column `name` in the expected columns (for the accessors below).
  std::size_t col(std::string_view name) const;
  /// True if the file has the optional columns.
  bool has_optional() const { return has_optional_; }

  std::string_view text(std::size_t c) const;
  bool empty(std::size_t c) const { return text(c).empty(); }
  std::int64_t integer(std::size_t c, std::int64_t lo = std::numeric_limits<std::int64_t>::min(),
                       std::int64_t hi = std::numeric_limits<std::int64_t>::max()) const;
  std::uint64_t unsigned_integer(std::size_t c, std::uint64_t hi = std::numeric_limits<std::uint64_t>::max()) const;
  /// A finite floating-point number.
  double number(std::size_t c) const;
  /// A finite number within [lo, hi]; fails naming `what` and the range otherwise (a value that
  /// no recording can hold, such as 1e308 for a position, would overflow what is computed from it).
  double number(std::size_t c, double lo, double hi, std::string_view what) const;

  /// Throws RecordingError at column `c` of the current row: `FILE:LINE:COL: NAME: what`.
  [[noreturn]] void fail(std::size_t c, const std::string& what) const;
  /// Throws RecordingError at the start of the current line (or `line`, if given).
  [[noreturn]] void fail_line(const std::string& what, int line = 0) const;

  int line() const { return line_; }  ///< 1-based line of the current row (1: the header)
  const std::string& name() const { return name_; }

 private:
  bool read_line();
  void split();
  /// `'text'` shortened and with control characters escaped, for messages.
  std::string quote(std::string_view s) const;

  std::istream& in_;
  std::string name_;
  std::vector<std::string> columns_;
  std::vector<std::size_t> position_;  ///< expected column → field index in the file
  std::string line_text_;
  bool line_ended_ = false;
  std::vector<std::string_view> fields_;
  std::vector<std::size_t> starts_;  ///< 0-based byte column of each field
  std::size_t bom_ = 0;              ///< bytes of a byte-order mark before the header (0 or 3)
  int line_ = 0;
  bool has_optional_ = false;
};

}  // namespace spidar::session
