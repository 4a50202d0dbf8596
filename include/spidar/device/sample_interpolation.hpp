#pragma once
/// Fingertip samples at a given time, e.g. a camera frame's exposure: the servo loop publishes a
/// sample per cycle (host time of its encoder reading); the frame pipeline interpolates the two
/// samples around the exposure time, linearly in positions, forces and tensions.
#include <cstdint>
#include <optional>
#include <span>

#include "spidar/core/seqlock.hpp"
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

/// Reads newest-first samples through `read(out, max)` (ServoLoop::newest_samples,
/// SimulatedSpidar::truth_samples) into `buf`, only as many as reach back to `t_ns`: first
/// `first`, then four times as many at each try, up to buf.size(). Returns how many it read; the
/// oldest of them is at or before `t_ns` unless the source holds no older one or `buf` is full.
///
/// A frame's exposure is a few milliseconds old when it is processed, and a copy of the whole
/// second a ring holds (1000 samples of about 800 bytes) cost more than 0.3 ms on the frame's
/// path, twice per frame (the camera's truth and the frame's fingertips).
template <class Read>
std::size_t read_back_to(Read&& read, std::int64_t t_ns, std::span<FingertipSample> buf,
                         std::size_t first = 32) {
  return core::read_newest_until(read, buf, [t_ns](const FingertipSample& s) { return s.t_ns <= t_ns; },
                                 first);
}

}  // namespace spidar::device
