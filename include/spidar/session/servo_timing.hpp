#pragma once
/// The servo loop's rate and jitter between two camera frames, from its published samples.
#include <cstdint>
#include <span>

#include "spidar/device/servo_types.hpp"

namespace spidar::session {

/// The servo loop's timing between two camera frames.
struct ServoTiming {
  double rate_hz = 0;        ///< cycles per second since the previous frame (0: not known yet)
  double jitter_max_us = 0;  ///< largest deviation of a period from the nominal one [µs]
};
/// From the loop's published samples, newest first (ServoLoop::newest_samples), those newer than
/// `*last_t_ns` (the newest seen at the previous frame; updated). `rate_hz`: nominal rate.
ServoTiming servo_timing_since(std::span<const device::FingertipSample> newest_first, double rate_hz,
                               std::int64_t* last_t_ns);

}  // namespace spidar::session
