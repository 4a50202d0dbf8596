#pragma once
// Session::run()'s interruption for tests that need a number of frames: they run until they have
// them, not for a time that a slow, loaded or sanitised run may fill with too few (the session's
// seconds, if any, are then only a backstop).
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

namespace spidar::session::testing {

/// The run ends, by "enough frames", once `count()` (a count the test's sinks keep) has reached
/// `n`.
template <class Count>
std::function<std::optional<std::string>()> after_frames(std::size_t n, Count count) {
  return [n, count]() -> std::optional<std::string> {
    if (static_cast<std::size_t>(count()) >= n) return std::string("enough frames");
    return std::nullopt;
  };
}

}  // namespace spidar::session::testing
