#pragma once
/// Replacing a file a user keeps (a device config, a camera calibration) without losing its
/// previous version: the old file is copied to `PATH.bak-YYYYmmdd-HHMMSS` (unique), the new text
/// written to `PATH.tmp` and renamed over PATH, so a reader never sees a half-written file.
#include <string>

namespace spidar::core {

/// Copies an existing file to `path.bak-YYYYmmdd-HHMMSS` (local time; `-2`, `-3`, … appended
/// while that name is taken) and returns that path; empty if `path` does not exist. Throws
/// FileError (core/file_read.hpp) if the copy fails.
std::string keep_previous_version(const std::string& path);

/// Writes `text` to `path`, keeping the previous file (returned, as keep_previous_version).
/// Throws FileError if the file cannot be written or replaced.
std::string replace_file_keeping_previous(const std::string& path, const std::string& text);

}  // namespace spidar::core
