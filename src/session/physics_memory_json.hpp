#pragma once
// The report's entry for MuJoCo's preallocated memory a run used (the demo's and the haptic
// scenario's report.json: physics.memory).
#include <nlohmann/json.hpp>

#include "spidar/physics/world.hpp"

namespace spidar::session {

inline nlohmann::json physics_memory_json(const physics::World::MemoryUse& u) {
  return {{"stack_words", u.stack_words},
          {"stack_words_max_used", u.stack_words_max_used},
          {"constraint_rows", u.constraint_rows},
          {"constraint_rows_max_used", u.constraint_rows_max_used},
          {"contacts", u.contacts},
          {"contacts_max_used", u.contacts_max_used}};
}

}  // namespace spidar::session
