#include "device_backends.hpp"

#include "cli_support.hpp"
#include "spidar/device/serial_device.hpp"
#include "spidar/device/simulated_spidar.hpp"

namespace spidar::app {

void add_backend_options(CLI::App& cmd, BackendArgs& a) {
  cmd.add_option("--config", a.config, "device config (YAML)")->capture_default_str();
  cmd.add_option("--backend", a.backend, "sim | serial")
      ->check(CLI::IsMember({"sim", "serial"}))
      ->capture_default_str();
  cmd.add_option("--port", a.port, "serial: device path, e.g. /dev/ttyACM0");
  cmd.add_option("--baud", a.baud, "serial: baud rate")->capture_default_str();
  cmd.add_flag("!--no-link-check", a.check_link_budget,
               "serial: do not refuse a rate whose frames exceed the baud rate (a pseudo-terminal, "
               "or a transport faster than its baud setting)");
  cmd.add_option("--seed", a.seed, "sim: random seed")->check(seed_check())->capture_default_str();
}

std::unique_ptr<device::Device> make_simulated(const strings::DeviceConfig& cfg, std::uint64_t seed) {
  device::SimulatedSpidarParams params;
  params.seed = seed;
  params.scale_error = 0.0;
  auto source = std::make_shared<device::ScriptedFingertips>(device::hovering_hands(device::rest_points(cfg)));
  return std::make_unique<device::SimulatedSpidar>(cfg, params, source);
}

std::unique_ptr<device::Device> make_backend(const BackendArgs& a, const strings::DeviceConfig& cfg) {
  if (a.backend == "sim") return make_simulated(cfg, a.seed);
  if (a.port.empty()) throw UsageError("--backend serial needs --port PATH (e.g. /dev/ttyACM0)");
  device::SerialDeviceConfig sc;
  sc.port = a.port;
  sc.baud = a.baud;
  sc.check_link_budget = a.check_link_budget;
  sc.string_count = cfg.string_count();
  sc.counter_bits = cfg.counter_bits;
  sc.command_min = cfg.command_range().min;
  sc.command_max = cfg.command_range().max;
  return std::make_unique<device::SerialDevice>(sc);
}

}  // namespace spidar::app
