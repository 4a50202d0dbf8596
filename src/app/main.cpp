// spidar-mr: command-line entry point. Bad input exits with code 2 and a message on stderr.
#include <CLI/CLI.hpp>
#include <cstdlib>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <filesystem>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "spidar/core/config.hpp"
#include "spidar/render/context.hpp"

int main(int argc, char** argv) {
  // Software GL renders in each drawing thread, at that thread's priority (on this 2-core VM: 18
  // fps instead of 15–16, latency median 75 instead of 90 ms, session 9). Before any thread or
  // GL context exists; an LP_NUM_THREADS of the user's wins.
  spidar::render::render_in_drawing_thread();
  // (Image files are read through vision::read_image, which checks the size a header declares:
  // OpenCV reads OPENCV_IO_MAX_IMAGE_PIXELS once, as its library loads, so setting it here would
  // not lower its bound.)
  using namespace spidar::app;
  // Logs and warnings (e.g. "SCHED_FIFO not permitted") go to stderr: stdout carries only the
  // command's result (JSON for device-test, position, tension).
  spdlog::set_default_logger(spdlog::stderr_color_mt("spidar-mr"));
  CLI::App app{"spidar-mr: SPIDAR-8 string haptics in mixed reality"};
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, Action>> actions;
  auto add = [&](Action (*adder)(CLI::App&)) {
    Action action = adder(app);
    actions.emplace_back(app.get_subcommands({}).back(), std::move(action));
  };
  add(add_check_config);
  add(add_position);
  add(add_tension);
  add(add_demo);
  add(add_device_test);
  add(add_emulate_device);
  add(add_calibrate_camera);
  add(add_render_test);
  add(add_run);
  add(add_replay);
  add(add_calibrate_strings);

  if (argc > 1 && argv[1][0] != '-') {
    std::string names;
    bool known = false;
    for (auto& [cmd, action] : actions) {
      known = known || cmd->get_name() == argv[1];
      names += (names.empty() ? "" : ", ") + cmd->get_name();
    }
    if (!known) {
      std::cerr << "spidar-mr: unknown subcommand '" << argv[1] << "'; expected one of: " << names
                << " (see spidar-mr --help)\n";
      return kExitBadInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }
  try {
    refuse_empty_values(app);
    for (auto& [cmd, action] : actions) {
      if (cmd->parsed()) return action();
    }
  } catch (const spidar::SpidarError& e) {
    std::cerr << "spidar-mr: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // An unwritable or misplaced output path: name it, it is the user's to fix.
    std::cerr << "spidar-mr: error: " << e.path1().string() << ": " << e.code().message() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "spidar-mr: internal error: " << e.what() << "\n";
    return 1;
  }
  return kExitBadInput;
}
