#pragma once
/// Fingertip samples at a given time, e.g. a camera frame's exposure: the servo loop publishes a
/// sample per cycle (host time of its encoder reading); the frame pipeline interpolates the two
/// samples around the exposure time, linearly in positions, forces and tensions.
#include <cstdint>
#include <optional>
#include <span>

#include "spidar/device/servo_types.hpp"

namespace spidar::device {

/// The sample at `t_ns` [ns, host monotonic] from samples given newest first (as
/// ServoLoop::newest_samples returns them; consecutive, strictly decreasing times).
/// - t between two samples: linear interpolation of p_W, f_W and (when both have the same
///   strings) the tensions; the commands and cycle of the earlier sample (in effect at t); t_ns = t;
///   faults and `consistent` of both OR-ed / AND-ed;
/// - t after the newest sample by at most `max_hold_ns`: the newest sample, held;
/// - otherwise (older than the oldest, too new, no samples): nullopt.
std::optional<FingertipSample> interpolate_samples(std::span<const FingertipSample> newest_first,
                                                   std::int64_t t_ns,
                                                   std::int64_t max_hold_ns = 5'000'000);

}  // namespace spidar::device
