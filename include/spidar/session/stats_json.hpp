#pragma once
/// Report entries shared by the commands that write a servo loop's or a physics thread's figures
/// (device-test, the demo's report.json, the haptic scenario's): one definition of their keys.
#include <nlohmann/json.hpp>

#include "spidar/device/servo_loop.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::session {

/// The servo loop's timing: rate_hz, jitter_p50_us / _p99_us / _max_us (|period − nominal|),
/// overruns, the cycle's compute time cycle_us_median / _p99 / _max, realtime_scheduling,
/// idle_spin, and the servo thread's servo_major_faults (page faults that waited for I/O) and
/// servo_involuntary_switches (times it was taken off its CPU). Each report adds its own keys
/// (faults, deadline misses, …) to it.
nlohmann::json servo_timing_json(const device::ServoStats& s);

/// MuJoCo's preallocated memory a run used (physics::World::memory_use): stack_words,
/// constraint_rows and contacts, each with its _max_used.
nlohmann::json physics_memory_json(const physics::World::MemoryUse& u);

}  // namespace spidar::session
