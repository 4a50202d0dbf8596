// spidar-mr demo: the best demonstration available (see demo.hpp for the scenarios).
#include <iostream>
#include <memory>

#include "cli_support.hpp"
#include "commands.hpp"
#include "demo.hpp"
#include "spidar/session/scenarios.hpp"

namespace spidar::app {

namespace {

session::ScenarioOptions scenario_options(const DemoOptions& o) {
  return {o.config, o.scene, o.out, o.seconds, o.rate_hz, o.seed, o.idle_spin != 0};
}

}  // namespace

int run_haptic_demo(const DemoOptions& o) {
  const device::ServoStats ss = session::run_haptic_scenario(scenario_options(o), std::cout);
  if (ss.faults == 0) return 0;
  std::cerr << "spidar-mr demo: the servo loop latched " << device::fault_names(ss.faults) << ": "
            << ss.fault_message << " (the report is written; exit code " << kExitFault << ")\n";
  return kExitFault;
}

int run_strings_demo(const DemoOptions& o) {
  session::run_strings_walkthrough(scenario_options(o), std::cout);
  return 0;
}

Action add_demo(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run a demonstration on the simulated SPIDAR-8");
  auto o = std::make_shared<DemoOptions>();
  cmd->add_option("--scenario", o->scenario,
                  "rubiks: the mixed-reality demo (device, physics, camera, registration, "
                  "compositing); haptic: the haptic part alone; strings: the device maths "
                  "walkthrough")
      ->check(CLI::IsMember({"rubiks", "haptic", "strings"}))
      ->capture_default_str();
  cmd->add_option("--config", o->config, "device config (YAML)")->capture_default_str();
  cmd->add_option("--scene", o->scene, "MJCF scene (rubiks, haptic)")->capture_default_str();
  cmd->add_option("--user-hand", o->user_hand,
                  "hands YAML of the simulated user (profile 'user', else the first)")
      ->capture_default_str();
  cmd->add_option("--model-hand", o->model_profile,
                  "profile in configs/hands.yaml of the registration's hand model (a user who "
                  "measured their hand names theirs)")
      ->capture_default_str();
  cmd->add_option("--camera", o->camera, "camera YAML (rubiks)")->capture_default_str();
  cmd->add_option("--width", o->width, "camera image width [px]")->capture_default_str();
  cmd->add_option("--height", o->height, "camera image height [px]")->capture_default_str();
  cmd->add_option("--fps", o->fps, "camera rate [Hz]")->capture_default_str();
  cmd->add_flag("--window", o->window, "show the mixed-reality view in a window");
  cmd->add_option("--compositor", o->compositor, "paper: the paper's cut-outs; depth: matte + model depth")
      ->check(CLI::IsMember({"paper", "depth"}))
      ->capture_default_str();
  cmd->add_flag("--fixed-hand-size", o->fixed_hand_size,
                "keep the model hand's sizes (default: estimate each hand's length and width online)");
  // Two flags that contradict each other are refused (CLI11 would take the last one given), here
  // and below.
  CLI::Option* ring_side = cmd->add_flag("--ring-on-side", o->ring_on_side,
                                         "the simulated user's left ring finger presses on the cube's left face: "
                                         "each finger on a face its strings can push it back from, so the layer "
                                         "turns with the cube moved or turned (the default)");
  cmd->add_flag("!--ring-on-back", o->ring_on_side,
                "the simulated user's left ring finger presses on the cube's back face, with the index and "
                "middle finger, and no --fit-margin unless given (the grasp before 2026-11-29: the layer's "
                "second turn fails with the cube turned or moved)")
      ->excludes(ring_side);
  cmd->add_option("--fit-margin", o->fit_margin_rad,
                  "how far inside its finger joints' ranges the simulated user's script is fitted to "
                  "their holding (left) hand [rad]: room for its fingers to follow caps pressed by the strings")
      ->check(range_check(0.0, 0.3, "rad"))
      ->capture_default_str();
  cmd->add_flag("--shaped-fingers", o->shaped_fingers,
                "the simulated user's fingertips yield only where their fingers can move (stiffness "
                "ellipsoids from their hands): their hands then reach the device's caps");
  CLI::Option* bending = cmd->add_flag("--bending-wrists", o->bending_wrists,
                                       "the simulated user's forearms point at elbows that stay where they were at "
                                       "the script's start, and their wrists bend (up to 60 deg) when the hands turn "
                                       "(the default)");
  cmd->add_flag("!--in-line-forearms", o->bending_wrists,
                "the simulated user's forearms stay in line with the hands, as the paper's model has them")
      ->excludes(bending);
  cmd->add_flag("!--paper-registration", o->silhouette,
                "register the main fit with the paper's joint-balls alone (default: joint-balls and "
                "the hand-aware silhouette term; the other method always runs as the comparison)");
  cmd->add_flag("!--no-video", o->video, "do not write mixed_reality.mp4");
  cmd->add_option("--out", o->out, "output directory")->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "length [s] (0: the scenario's own)");
  cmd->add_option("--rate", o->rate_hz, "servo rate [Hz]")->capture_default_str();
  CLI::Option* spin = cmd->add_flag_callback("--idle-spin", [o] { o->idle_spin = 1; },
                                             "keep the servo's CPU from halting before each cycle (a SCHED_IDLE "
                                             "thread; the haptic scenario's default; docs/realtime.md)");
  cmd->add_flag_callback("--no-idle-spin", [o] { o->idle_spin = 0; }, "let the servo's CPU halt between cycles "
                         "(the rubiks scenario's default)")
      ->excludes(spin);
  cmd->add_option("--seed", o->seed, "random seed")->check(seed_check())->capture_default_str();
  // Options of the mixed-reality demo alone (the camera, the hands, the registration, the video)
  // are a mistake with the haptic or strings scenario, which would ignore them.
  cmd->parse_complete_callback([cmd, o] {
    // The old grasp as it was: with the ring on the back face, no margin unless one is given (a
    // 0.1 rad margin with that grasp failed the second turn in the demo: docs/measurements.md).
    if (!o->ring_on_side && cmd->get_option("--fit-margin")->count() == 0) o->fit_margin_rad = 0.0;
    if (o->scenario == "rubiks") return;
    for (const CLI::Option* opt : cmd->get_options()) {
      if (opt->count() == 0) continue;
      const std::string name = opt->get_name();
      const bool everywhere = name == "--scenario" || name == "--config" || name == "--out" || name == "--seconds" ||
                              name == "--rate" || name == "--idle-spin" || name == "--no-idle-spin" ||
                              name == "--seed" || name == "--help";
      if (everywhere || (name == "--scene" && o->scenario == "haptic")) continue;
      throw CLI::ValidationError(name, "applies to --scenario " + std::string(name == "--scene" ? "rubiks or haptic" : "rubiks") +
                                           ", not to --scenario " + o->scenario);
    }
  });
  return [o] {
    require_range(o->seconds, 0, 600, "--seconds", "s");
    require_range(o->rate_hz, 10, 20000, "--rate", "Hz");
    require_range(o->width, 64, 3840, "--width", "px");
    require_range(o->height, 48, 2160, "--height", "px");
    require_range(o->fps, 1, 240, "--fps", "Hz");
    check_output_dir(o->out, "--out");
    if (o->scenario == "strings") return run_strings_demo(*o);
    if (o->scenario == "haptic") return run_haptic_demo(*o);
    return run_mr_demo(*o);
  };
}

}  // namespace spidar::app
