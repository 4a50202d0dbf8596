#include "spidar/sim/script_schedule.hpp"

#include <algorithm>

namespace spidar::sim {

const ScriptSegment& ScriptSchedule::at(double t) const {
  for (std::int32_t k = count - 1; k > 0; --k) {
    if (segments[static_cast<std::size_t>(k)].t0_s <= t) return segments[static_cast<std::size_t>(k)];
  }
  return segments[0];
}

double ScriptSchedule::script_time(double t) const {
  const ScriptSegment& s = at(t);
  return std::max(0.0, s.s0_s + (t - s.t0_s));
}

void ScriptSchedule::start(const ScriptSegment& s) {
  if (count == kMaxSegments) {
    std::rotate(segments.begin(), segments.begin() + 1, segments.end());
    --count;
  }
  segments[static_cast<std::size_t>(count++)] = s;
}

double blend_weight(const ScriptSegment& seg, double t) {
  if (seg.blend_s <= 0) return 1.0;
  const double x = std::clamp((t - seg.t0_s) / seg.blend_s, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace spidar::sim
