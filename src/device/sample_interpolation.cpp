#include "spidar/device/sample_interpolation.hpp"

#include <algorithm>

namespace spidar::device {

std::optional<FingertipSample> interpolate_samples(std::span<const FingertipSample> s,
                                                   std::int64_t t_ns, std::int64_t max_hold_ns) {
  if (s.empty()) return std::nullopt;
  if (t_ns >= s.front().t_ns) {
    if (t_ns - s.front().t_ns > max_hold_ns) return std::nullopt;
    FingertipSample held = s.front();
    held.t_ns = t_ns;
    return held;
  }
  // s is newest first: find the first (newest) sample at or before t; its predecessor in the span
  // is the one after t. Binary search on decreasing times.
  const auto it = std::partition_point(s.begin(), s.end(),
                                       [&](const FingertipSample& x) { return x.t_ns > t_ns; });
  if (it == s.end()) return std::nullopt;  // older than the oldest
  const FingertipSample& a = *it;          // at or before t
  const FingertipSample& b = *(it - 1);    // after t
  const double span = static_cast<double>(b.t_ns - a.t_ns);
  const double w = span > 0 ? static_cast<double>(t_ns - a.t_ns) / span : 0.0;
  FingertipSample out = a;
  out.t_ns = t_ns;
  out.faults = a.faults | b.faults;
  out.consistent = a.consistent & b.consistent;
  out.finger_count = std::min(a.finger_count, b.finger_count);
  for (int f = 0; f < out.finger_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      out.p_W[f][k] = a.p_W[f][k] + w * (b.p_W[f][k] - a.p_W[f][k]);
      out.f_W[f][k] = a.f_W[f][k] + w * (b.f_W[f][k] - a.f_W[f][k]);
    }
  }
  // Tensions interpolate like forces; commands are the ones in effect at t (a's).
  if (a.string_count == b.string_count) {
    for (int k = 0; k < out.string_count; ++k) out.tension[k] = a.tension[k] + w * (b.tension[k] - a.tension[k]);
  }
  return out;
}

}  // namespace spidar::device
