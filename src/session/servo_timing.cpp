#include "spidar/session/servo_timing.hpp"

#include <algorithm>
#include <cmath>

#include "spidar/core/clock.hpp"

namespace spidar::session {

ServoTiming servo_timing_since(std::span<const device::FingertipSample> s, double rate_hz,
                               std::int64_t* last_t_ns) {
  ServoTiming out;
  int cycles = 0;
  const double nominal_us = 1e6 / rate_hz;
  for (std::size_t k = 0; k + 1 < s.size() && s[k].t_ns > *last_t_ns; ++k) {
    ++cycles;
    out.jitter_max_us = std::max(out.jitter_max_us, std::abs(core::ns_to_s(s[k].t_ns - s[k + 1].t_ns) * 1e6 - nominal_us));
  }
  if (!s.empty() && *last_t_ns > 0 && cycles > 0) out.rate_hz = cycles / core::ns_to_s(s[0].t_ns - *last_t_ns);
  if (!s.empty()) *last_t_ns = s[0].t_ns;
  return out;
}

}  // namespace spidar::session
