#pragma once
/// Building a device backend by name: the simulated SPIDAR (hovering hands) or a serial device.
#include <cstdint>
#include <memory>
#include <string>

#include "spidar/device/device.hpp"
#include "spidar/device/serial_device.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::session {

struct BackendArgs {
  std::string config = "configs/spidar8.yaml";
  std::string backend = "sim";  ///< sim | serial
  std::string port;             ///< serial: tty path
  int baud = 2000000;  ///< enough for 24 strings at 1 kHz (link_budget.hpp)
  bool check_link_budget = true;  ///< false: a pty or a transport faster than its baud setting
  /// serial: the device is lost after this long without a reading [s] (SerialDeviceConfig::
  /// read_timeout_s: (0, 1] s, and at least two servo periods).
  double read_timeout_s = device::SerialDeviceConfig{}.read_timeout_s;
  std::uint64_t seed = 1;
};

/// The device named by `a` (not yet open). SpidarError on a serial backend without a port.
std::unique_ptr<device::Device> make_backend(const BackendArgs& a, const strings::DeviceConfig& cfg);
/// The simulated SPIDAR with hovering hands (also the backend of emulate-device).
std::unique_ptr<device::Device> make_simulated(const strings::DeviceConfig& cfg, std::uint64_t seed);

}  // namespace spidar::session
