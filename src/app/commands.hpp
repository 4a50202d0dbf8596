#pragma once
/// The spidar-mr subcommands. Each registers itself on the CLI11 app and runs when chosen.
#include <CLI/CLI.hpp>
#include <functional>

namespace spidar::app {

/// A subcommand's action; returns the process exit code.
using Action = std::function<int()>;

Action add_check_config(CLI::App& app);
Action add_position(CLI::App& app);
Action add_tension(CLI::App& app);
Action add_demo(CLI::App& app);
Action add_device_test(CLI::App& app);
Action add_emulate_device(CLI::App& app);
Action add_calibrate_camera(CLI::App& app);
Action add_render_test(CLI::App& app);
// The live application (cmd_run.cpp, cmd_replay.cpp, cmd_calibrate_strings.cpp).
Action add_run(CLI::App& app);
Action add_replay(CLI::App& app);
Action add_calibrate_strings(CLI::App& app);

}  // namespace spidar::app
