#pragma once
/// Writing a whole output file so that it is either the new content or the old one, never a
/// mixture or a truncated file (report.json, session.json, calibrated configs).
///
/// `write_file_atomic(path, bytes)`:
///   - follows `path` through symbolic links (a chain of them, relative or absolute) to the file
///     it names, and replaces that file: the links stay links and now show the new content;
///   - refuses a target that exists and is not a regular file (a directory, a device such as
///     /dev/null, a FIFO): replacing those by renaming over them would be a surprise;
///   - writes the bytes to a new temporary file beside the target (`.NAME.tmp-PID-N`, created
///     with O_EXCL and the usual 0666 & ~umask permissions, or the target's permissions if it
///     exists), checks every write, optionally fsyncs it, and renames it over the target;
///   - on any failure removes the temporary file, leaves the target as it was, and throws
///     `FileError(path, reason)`, where the reason names the target when `path` was a link and
///     says what failed (`write failed: No space left on device`).
#include <string>
#include <string_view>

#include "spidar/core/file_read.hpp"

namespace spidar::core {

struct AtomicWriteOptions {
  /// fsync the file before the rename and its folder after it (durable across a power cut).
  bool sync = true;
};

/// Replaces the file at `path` (resolved through symbolic links) with `bytes`. Throws FileError.
void write_file_atomic(const std::string& path, std::string_view bytes,
                       const AtomicWriteOptions& options = {});

/// The file `path` names after following symbolic links (at most 40); `path` itself if it is
/// not a link. The final target need not exist (a dangling link names the file to create).
/// Throws FileError on a link loop or an unreadable link.
std::string resolve_symlinks(const std::string& path);

}  // namespace spidar::core
