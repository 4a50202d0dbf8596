#include "device_backends.hpp"

#include "cli_support.hpp"

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
  cmd.add_option("--read-timeout", a.read_timeout_s,
                 "serial: seconds without a reading after which the device counts as lost (a read "
                 "timeout fault)")
      ->check(CLI::Range(1e-3, 10.0))
      ->capture_default_str();
  cmd.add_option("--seed", a.seed, "sim: random seed")->check(seed_check())->capture_default_str();
}

}  // namespace spidar::app
