#include "device_backends.hpp"

#include "cli_support.hpp"

namespace spidar::app {

void add_backend_options(CLI::App& cmd, BackendArgs& a) {
  cmd.add_option("--config", a.config, "device config (YAML)")->capture_default_str();
  cmd.add_option("--backend", a.backend, "sim | serial")
      ->check(CLI::IsMember({"sim", "serial"}))
      ->capture_default_str();
  CLI::Option* port = cmd.add_option("--port", a.port, "serial: device path, e.g. /dev/ttyACM0");
  CLI::Option* baud = cmd.add_option("--baud", a.baud, "serial: baud rate")->capture_default_str();
  CLI::Option* link = cmd.add_flag("!--no-link-check", a.check_link_budget,
               "serial: do not refuse a rate whose frames exceed the baud rate (a pseudo-terminal, "
               "or a transport faster than its baud setting)");
  CLI::Option* timeout = cmd.add_option("--read-timeout", a.read_timeout_s,
                                        "serial: seconds without a reading after which the device "
                                        "counts as lost (a read timeout fault)")
                             ->check(range_check(1e-3, device::kMaxReadTimeout_s, "s"))
                             ->capture_default_str();
  CLI::Option* seed = cmd.add_option("--seed", a.seed, "sim: random seed")->check(seed_check())->capture_default_str();
  // An option of the other backend is a mistake worth saying (a --port with --backend sim would
  // otherwise run the simulation while the user thinks the hardware is driven).
  cmd.parse_complete_callback([&a, port, baud, link, timeout, seed] {
    const bool serial = a.backend == "serial";
    for (const CLI::Option* o : serial ? std::vector<const CLI::Option*>{seed}
                                       : std::vector<const CLI::Option*>{port, baud, link, timeout})
      if (o->count() > 0)
        throw CLI::ValidationError(o->get_name(), "applies to --backend " + std::string(serial ? "sim" : "serial") +
                                                      ", not to --backend " + a.backend);
  });
}

}  // namespace spidar::app
