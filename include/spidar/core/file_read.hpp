#pragma once
/// Reading a whole input file into memory with a size limit, for anything we read from a path a
/// user gave us (configs, recordings, CSV, marker files).
///
/// `read_file_bounded` refuses, before reading a byte:
///   - a path that contains a NUL character (`std::string` can hold one; the OS would cut there),
///   - a path that does not exist or cannot be opened,
///   - a directory, and anything that is not a regular file (FIFO, socket, character or block
///     device such as `/dev/zero`): the type is checked with `stat` before opening, and the open
///     is non-blocking, so a FIFO never blocks the caller,
///   - a file whose size is above the limit.
/// It then reads at most `max_bytes + 1` bytes, so a file that grows while we read it, or one
/// whose size `stat` does not know, cannot exhaust memory either. `max_bytes` is in bytes.
#include <cstddef>
#include <string>
#include <string_view>

#include "spidar/core/result.hpp"

namespace spidar::core {

/// A file that could not be read, or was refused. `what()` is `PATH: reason`, with control
/// characters in PATH written as `\xNN` (see `printable_for_message`) so a hostile name cannot
/// forge lines in a log.
class FileError : public SpidarError {
 public:
  FileError(std::string path, std::string reason);
  const std::string& path() const { return path_; }      ///< the path as given
  const std::string& reason() const { return reason_; }  ///< e.g. `is a directory`

 private:
  std::string path_;
  std::string reason_;
};

/// The bytes of the regular file at `path`, at most `max_bytes` of them.
/// `what` names the kind of file for the size message, e.g. "a config file" gives
/// `PATH: 52428800 bytes, more than the 1048576 allowed for a config file`.
/// Throws FileError with one of these reasons:
///   `path contains a NUL character`, `cannot open file (does it exist and is it readable?)`,
///   `is a directory`, `is not a regular file`, `N bytes, more than the M allowed for WHAT`,
///   `more than the M bytes allowed for WHAT (it grew while being read, or its size was not
///   known)` (files in /proc report size 0), `read failed: REASON`.
std::string read_file_bounded(const std::string& path, std::size_t max_bytes,
                              std::string_view what);

/// `text` with control characters (bytes below 0x20, and 0x7f) written as `\xNN`, for file
/// names in messages; other bytes, UTF-8 included, are kept.
std::string printable_for_message(std::string_view text);

}  // namespace spidar::core
