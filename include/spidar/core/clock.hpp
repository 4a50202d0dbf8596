#pragma once
/// Monotonic time for real-time loops (CLOCK_MONOTONIC, nanoseconds).
#include <cstdint>

namespace spidar::core {

/// Nanoseconds on the monotonic clock.
std::int64_t monotonic_ns();
/// Sleeps until the monotonic clock reads `t_ns` (absolute deadline; no drift accumulates).
void sleep_until_ns(std::int64_t t_ns);

inline constexpr double ns_to_s(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }
inline constexpr std::int64_t s_to_ns(double s) { return static_cast<std::int64_t>(s * 1e9); }

}  // namespace spidar::core
