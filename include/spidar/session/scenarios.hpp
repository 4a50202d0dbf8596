#pragma once
/// The demo scenarios without a camera (`spidar-mr demo --scenario haptic|strings`): each runs on
/// the simulated SPIDAR-8, prints its progress and summary to `out` and writes its files (a
/// trace CSV and report.json) into ScenarioOptions::out. Throws SpidarError for bad input
/// (a config or scene that does not load, a scene without a Rubik's cube).
#include <cstdint>
#include <ostream>
#include <string>

#include "spidar/device/servo_loop.hpp"

namespace spidar::session {

struct ScenarioOptions {
  std::string config = "configs/spidar8.yaml";  ///< device config (resolve_data_path)
  std::string scene = "scenes/rubiks_cube.xml";  ///< MJCF scene (haptic)
  std::string out = "out/demo";                  ///< output folder (created)
  double seconds = 0;                            ///< 0: the scenario's own length [s]
  double rate_hz = 1000.0;                       ///< servo rate [Hz]
  std::uint64_t seed = 1;
  bool idle_spin = true;                         ///< device::ServoConfig::idle_spin
};

/// The left hand lifts the Rubik's cube, the right hand turns its top layer (simulated device,
/// servo loop, physics thread): haptic_trace.csv and report.json. Returns the servo loop's
/// statistics (a latched fault is in `faults`, `fault_message`).
device::ServoStats run_haptic_scenario(const ScenarioOptions& o, std::ostream& out);

/// The device maths walkthrough: calibration, force cones, a scripted grasp of a virtual box:
/// walkthrough.csv and report.json.
void run_strings_walkthrough(const ScenarioOptions& o, std::ostream& out);

}  // namespace spidar::session
