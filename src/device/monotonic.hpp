#pragma once
/// The host's monotonic clock for the device sources (private header).
#include <time.h>

#include <cstdint>

namespace spidar::device {

/// CLOCK_MONOTONIC [ns].
inline std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace spidar::device
