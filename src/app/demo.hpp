#pragma once
/// The scenarios of `spidar-mr demo`.
#include <cstdint>
#include <string>

namespace spidar::app {

struct DemoOptions {
  std::string scenario = "rubiks";  ///< rubiks | haptic | strings
  std::string config = "configs/spidar8.yaml";
  std::string scene = "scenes/rubiks_cube.xml";
  std::string out = "out/demo";
  double seconds = 0;               ///< 0: the scenario's own length
  double rate_hz = 1000.0;
  /// Keep the servo's CPU from halting (device::ServoConfig::idle_spin): 1 on, 0 off, −1 the
  /// scenario's default (on for haptic, off for rubiks, whose frame pipeline it slows).
  int idle_spin = -1;
  std::uint64_t seed = 1;
  // rubiks (the mixed-reality demo)
  std::string user_hand = "configs/hands.yaml";  ///< the simulated user's hands (profile "user")
  std::string user_profile = "user";
  std::string model_profile = "model";  ///< the registration's hand sizes (configs/hands.yaml)
  std::string camera = "configs/camera.yaml";
  int width = 640, height = 480;   ///< camera image [px]
  double fps = 30.0;               ///< camera rate [Hz]
  bool window = false;
  std::string compositor = "depth";
  bool silhouette = true;          ///< the silhouette term in the main registration
  bool fixed_hand_size = false;    ///< no online hand-size personalisation (on in the demo)
  bool bending_wrists = true;      ///< the user's wrists bend: forearms point at fixed elbows
  bool shaped_fingers = false;     ///< the user's fingertips held with their fingers' stiffness
  bool ring_on_side = true;        ///< the user's left ring finger on the cube's left face
  double fit_margin_rad = 0.1;     ///< session::ScriptedUserOptions::fit_limit_margin_rad (holding hand)
  bool video = true;
};

/// The left hand lifts the Rubik's cube, the right hand turns its top layer (simulated device,
/// servo loop, physics thread).
int run_haptic_demo(const DemoOptions& o);
/// The mixed-reality demo (`make demo`): the scripted user turns the cube's layers with both
/// hands; simulated device, physics, synthetic camera, registration, rendering, compositing.
int run_mr_demo(const DemoOptions& o);
/// The device maths walkthrough: calibration, force cones, a scripted grasp of a virtual box.
int run_strings_demo(const DemoOptions& o);

}  // namespace spidar::app
