#include "spidar/session/device_backends.hpp"

#include "spidar/device/serial_device.hpp"
#include "spidar/device/simulated_spidar.hpp"

namespace spidar::session {

std::unique_ptr<device::Device> make_simulated(const strings::DeviceConfig& cfg, std::uint64_t seed) {
  device::SimulatedSpidarParams params;
  params.seed = seed;
  params.scale_error = 0.0;
  auto source = std::make_shared<device::ScriptedFingertips>(device::hovering_hands(device::rest_points(cfg)));
  return std::make_unique<device::SimulatedSpidar>(cfg, params, source);
}

std::unique_ptr<device::Device> make_backend(const BackendArgs& a, const strings::DeviceConfig& cfg) {
  if (a.backend == "sim") return make_simulated(cfg, a.seed);
  if (a.port.empty()) throw SpidarError("--backend serial needs --port PATH (e.g. /dev/ttyACM0)");
  device::SerialDeviceConfig sc;
  sc.port = a.port;
  sc.baud = a.baud;
  sc.check_link_budget = a.check_link_budget;
  sc.read_timeout_s = a.read_timeout_s;
  sc.string_count = cfg.string_count();
  sc.counter_bits = cfg.counter_bits;
  sc.command_min = cfg.command_range().min;
  sc.command_max = cfg.command_range().max;
  return std::make_unique<device::SerialDevice>(sc);
}

}  // namespace spidar::session
