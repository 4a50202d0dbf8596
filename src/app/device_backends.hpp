#pragma once
/// Choosing and building a device backend from command-line options.
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "spidar/device/device.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::app {

struct BackendArgs {
  std::string config = "configs/spidar8.yaml";
  std::string backend = "sim";  ///< sim | serial
  std::string port;             ///< serial: tty path
  int baud = 2000000;  ///< enough for 24 strings at 1 kHz (link_budget.hpp)
  bool check_link_budget = true;  ///< false: a pty or a transport faster than its baud setting
  std::uint64_t seed = 1;
};

void add_backend_options(CLI::App& cmd, BackendArgs& a);
/// The device named by the options (not yet open). UsageError on bad options.
std::unique_ptr<device::Device> make_backend(const BackendArgs& a, const strings::DeviceConfig& cfg);
/// The simulated SPIDAR with hovering hands (also the backend of emulate-device).
std::unique_ptr<device::Device> make_simulated(const strings::DeviceConfig& cfg, std::uint64_t seed);

}  // namespace spidar::app
