// spidar-mr device-test: run the servo loop on a device with zero desired force and report
// loop statistics as JSON.
#include <iostream>
#include <memory>
#include <sstream>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "device_backends.hpp"
#include "signal_scope.hpp"
#include "spidar/device/serial_device.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/session/stats_json.hpp"

namespace spidar::app {
Action add_device_test(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "device-test", "Run the servo loop with zero force and print loop statistics (JSON)");
  auto a = std::make_shared<BackendArgs>();
  auto seconds = std::make_shared<double>(3.0);
  auto rate = std::make_shared<double>(1000.0);
  auto idle_spin = std::make_shared<bool>(true);
  add_backend_options(*cmd, *a);
  cmd->add_option("--seconds", *seconds, "how long to run [s]")->capture_default_str();
  cmd->add_option("--rate", *rate, "servo rate [Hz]")->capture_default_str();
  cmd->add_flag("!--no-idle-spin", *idle_spin,
                "let the servo's CPU halt between cycles (by default a SCHED_IDLE thread keeps it from "
                "halting before each cycle: docs/realtime.md)");
  return [a, seconds, rate, idle_spin] {
    require_above(*seconds, 0, 3600, "--seconds", "s");
    require_range(*rate, 10, 20000, "--rate", "Hz");
    const auto cfg = strings::load_device_config(resolve_data_path(a->config));
    auto dev = make_backend(*a, cfg);
    if (auto st = dev->open(); !st.ok()) throw UsageError(st.error().message);

    device::ServoConfig servo;
    servo.rate_hz = *rate;
    servo.idle_spin = *idle_spin;
    servo.max_seconds = *seconds;
    device::ServoLoop loop(*dev, cfg, servo, std::make_shared<device::ZeroForce>());
    SignalScope signals;  // SIGINT / SIGTERM end the run early, with its statistics printed
    if (auto st = loop.start(); !st.ok()) throw UsageError(st.error().message);
    while (loop.running() && SignalScope::received() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    loop.stop();
    dev->close();

    const auto s = loop.stats();
    nlohmann::json faults = nlohmann::json::array();
    if (s.faults) {
      std::string names = device::fault_names(s.faults);
      for (std::size_t pos = 0; pos != std::string::npos;) {
        const auto comma = names.find(',', pos);
        faults.push_back(names.substr(pos, comma == std::string::npos ? comma : comma - pos));
        pos = comma == std::string::npos ? comma : comma + 1;
      }
    }
    nlohmann::json fingers = nlohmann::json::array();
    device::FingertipSample last;
    if (loop.newest_samples(&last, 1) == 1) {
      for (int f = 0; f < last.finger_count; ++f) {
        // What the last cycle computed and sent, read from its sample (not solved again).
        nlohmann::json tensions = nlohmann::json::array(), commands = nlohmann::json::array();
        for (int i = 0, k = cfg.first_string(f); i < cfg.fingers[f].geometry.n && k < last.string_count; ++i, ++k) {
          tensions.push_back(last.tension[static_cast<std::size_t>(k)]);
          commands.push_back(last.command[static_cast<std::size_t>(k)]);
        }
        fingers.push_back({{"finger", f},
                           {"name", cfg.fingers[f].name},
                           {"position", to_json(device::fingertip_position(last, f))},
                           {"force_n", to_json(device::fingertip_force(last, f))},
                           {"tensions_n", tensions},
                           {"commands", commands},
                           {"consistent", ((last.consistent >> f) & 1u) != 0}});
      }
    }
    nlohmann::json j = session::servo_timing_json(s);
    j.update({{"device", dev->info().name},
              {"rate_target_hz", *rate},
              {"cycles", s.cycles},
              {"seconds", s.seconds},
              {"deadline_misses", s.deadline_misses},
              {"stale_force_cycles", s.stale_force_cycles},
              {"repeated_readings", s.repeated_readings},
              {"longest_repeat", s.longest_repeat},
              {"inconsistent_solves", s.inconsistent},
              {"faults", faults},
              {"fault_message", s.fault_message},
              {"fingertips", fingers}});
    if (const auto* serial = dynamic_cast<const device::SerialDevice*>(dev.get())) {
      const device::SerialLinkStats l = serial->link_stats();
      j["serial_link"] = {{"frames_out", l.frames_out},     {"counts_in", l.counts_in},
                          {"stale", l.stale},               {"behind", l.behind},
                          {"repeated", l.repeated},         {"timeouts", l.timeouts},
                          {"unexpected", l.unexpected},     {"decoder_errors", l.decoder.errors()}};
    }
    require_finite_json(j, "device-test report");
    std::cout << session::json_text(j, 2) << "\n";
    return s.faults ? 1 : 0;
  };
}

}  // namespace spidar::app
