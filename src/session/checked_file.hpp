#pragma once
// A file written in appended chunks (a recording's CSVs, which grow while a session runs and so
// cannot be written atomically), where every failure is caught: each write(2) is checked, and
// close() flushes, fsyncs and closes, checking each step. The first failure is kept as a
// FileError naming the path and the reason (e.g. "write failed: No space left on device");
// later writes do nothing, and close() throws it.
#include <string>
#include <string_view>

#include "spidar/core/file_read.hpp"

namespace spidar::session {

class CheckedFile {
 public:
  /// Creates or truncates `path` (following symbolic links). Throws FileError.
  explicit CheckedFile(std::string path);
  ~CheckedFile();
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  /// Appends `text` (buffered). Returns false once any write has failed.
  bool write(std::string_view text);
  /// Flushes, fsyncs and closes; throws the first failure as FileError. Idempotent.
  void close();
  bool ok() const { return error_.empty(); }
  /// The first failure, empty if none.
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }

 private:
  bool flush();
  void fail(const std::string& reason);

  std::string path_;
  int fd_ = -1;
  std::string buffer_;
  std::string error_;
  std::string reason_;
};

}  // namespace spidar::session
