#pragma once
// The ConfigError message a config test expects, shared by the core suites.
#include <functional>
#include <string>

#include "spidar/core/config.hpp"

namespace spidar::core::testing {

/// The ConfigError message of `fn`, or "no error". Any other exception fails the test.
inline std::string error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace spidar::core::testing
