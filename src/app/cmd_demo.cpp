// spidar-mr demo: the best demonstration available (see demo.hpp for the scenarios).
#include <memory>

#include "cli_support.hpp"
#include "commands.hpp"
#include "demo.hpp"

namespace spidar::app {

Action add_demo(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run a demonstration on the simulated SPIDAR-8");
  auto o = std::make_shared<DemoOptions>();
  cmd->add_option("--scenario", o->scenario,
                  "haptic: two hands lift the Rubik's cube and turn a layer; strings: the device "
                  "maths walkthrough")
      ->check(CLI::IsMember({"haptic", "strings"}))
      ->capture_default_str();
  cmd->add_option("--config", o->config, "device config (YAML)")->capture_default_str();
  cmd->add_option("--scene", o->scene, "MJCF scene (haptic)")->capture_default_str();
  cmd->add_option("--out", o->out, "output directory")->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "length [s] (0: the scenario's own)");
  cmd->add_option("--rate", o->rate_hz, "servo rate [Hz]")->capture_default_str();
  cmd->add_option("--seed", o->seed, "random seed")->capture_default_str();
  return [o] {
    if (o->seconds < 0 || o->seconds > 600) throw UsageError("--seconds: expected 0 to 600");
    if (!(o->rate_hz >= 10 && o->rate_hz <= 20000)) throw UsageError("--rate: expected 10 to 20000 Hz");
    return o->scenario == "strings" ? run_strings_demo(*o) : run_haptic_demo(*o);
  };
}

}  // namespace spidar::app
