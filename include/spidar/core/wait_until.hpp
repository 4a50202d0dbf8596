#pragma once
/// Waiting on a condition variable up to a deadline on the session's clock (core::monotonic_ns),
/// as the frame sources' wait_for_frame do: spurious wake-ups and early timeouts go round again.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "spidar/core/clock.hpp"

namespace spidar::core {

/// Waits on `cv`, with `lock` held on entry and return, until `done()` is true or monotonic_ns()
/// reaches `deadline_ns`. Returns done() at the end.
template <class Done>
bool wait_until_ns(std::condition_variable& cv, std::unique_lock<std::mutex>& lock, std::int64_t deadline_ns,
                   Done done) {
  while (!done()) {
    const std::int64_t left = deadline_ns - monotonic_ns();
    if (left <= 0) return false;
    cv.wait_for(lock, std::chrono::nanoseconds(left));
  }
  return true;
}

}  // namespace spidar::core
