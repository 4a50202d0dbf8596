#pragma once
/// UTF-8 checks for text read from files (configuration names, labels): JSON output and most
/// terminals take UTF-8 only, so text that is not is refused where it is read, with its place.
#include <cstddef>
#include <optional>
#include <string_view>

namespace spidar::core {

/// The offset of the first byte of `text` that does not begin or continue a well-formed UTF-8
/// sequence (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF); nullopt when all of
/// it is well formed.
std::optional<std::size_t> first_invalid_utf8(std::string_view text);

}  // namespace spidar::core
