#pragma once
/// The scenarios of `spidar-mr demo`.
#include <cstdint>
#include <string>

namespace spidar::app {

struct DemoOptions {
  std::string scenario = "haptic";  ///< haptic | strings
  std::string config = "configs/spidar8.yaml";
  std::string scene = "scenes/rubiks_cube.xml";
  std::string out = "out/demo";
  double seconds = 0;               ///< 0: the scenario's own length
  double rate_hz = 1000.0;
  std::uint64_t seed = 1;
};

/// The left hand lifts the Rubik's cube, the right hand turns its top layer (simulated device,
/// servo loop, physics thread).
int run_haptic_demo(const DemoOptions& o);
/// The device maths walkthrough: calibration, force cones, a scripted grasp of a virtual box.
int run_strings_demo(const DemoOptions& o);

}  // namespace spidar::app
