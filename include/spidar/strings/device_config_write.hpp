#pragma once
/// Writing calibrated encoder channels back into a device config file, keeping the user's
/// comments and layout, and the previous version of the file beside it.
#include <span>
#include <string>

#include "spidar/strings/encoder.hpp"

namespace spidar::strings {

/// The device config text with finger `finger`'s channels replaced: `length_at_zero` always,
/// `signs` and `metres_per_count` too with `full` (multi-point). Other text is kept; a comment
/// on the new line notes the calibration (`note`). `source` names the text in messages. Throws
/// SpidarError if the finger's block (a line `- name: <finger>`) is not found.
std::string with_finger_channels(const std::string& yaml, const std::string& source,
                                 const std::string& finger,
                                 std::span<const EncoderChannel> channels, bool full,
                                 const std::string& note);

/// Writes `text` to the device config at `path`, keeping the previous file as
/// `path.bak-YYYYmmdd-HHMMSS` (returned; empty if there was none). The text must parse as a
/// device config first (else core::ConfigError, and the file is untouched); core::FileError if
/// it cannot be written.
std::string write_device_config(const std::string& path, const std::string& text);

}  // namespace spidar::strings
