#include "spidar/session/stats_json.hpp"

namespace spidar::session {

nlohmann::json servo_timing_json(const device::ServoStats& s) {
  return {{"rate_hz", s.rate_hz},
          {"jitter_p50_us", s.jitter_p50_us},
          {"jitter_p99_us", s.jitter_p99_us},
          {"jitter_max_us", s.jitter_max_us},
          {"overruns", s.overruns},
          {"cycle_us_median", s.cycle_us_median},
          {"cycle_us_p99", s.cycle_us_p99},
          {"cycle_us_max", s.cycle_us_max},
          {"realtime_scheduling", s.realtime_scheduling},
          {"idle_spin", s.idle_spin},
          {"servo_major_faults", s.major_faults},
          {"servo_involuntary_switches", s.involuntary_switches}};
}

nlohmann::json physics_memory_json(const physics::World::MemoryUse& u) {
  return {{"stack_words", u.stack_words},
          {"stack_words_max_used", u.stack_words_max_used},
          {"constraint_rows", u.constraint_rows},
          {"constraint_rows_max_used", u.constraint_rows_max_used},
          {"contacts", u.contacts},
          {"contacts_max_used", u.contacts_max_used}};
}

}  // namespace spidar::session
