// spidar-mr emulate-device --pty: serves the device side of the serial protocol on a
// pseudo-terminal, backed by the simulated SPIDAR, so the serial path runs without hardware.
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <cstring>

#include <csignal>
#include <iostream>
#include <memory>
#include <thread>

#include "cli_support.hpp"
#include "spidar/core/realtime.hpp"
#include "commands.hpp"
#include "device_backends.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/device_emulator.hpp"
#include "spidar/device/serial_port.hpp"

namespace spidar::app {
namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }
}  // namespace

Action add_emulate_device(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "emulate-device",
      "Serve a simulated SPIDAR over the serial protocol on a pseudo-terminal; prints its path");
  struct Args {
    std::string config = "configs/spidar8.yaml";
    bool pty = false;
    double seconds = 0;
    double heartbeat_timeout = 0.1;
    std::uint64_t seed = 1;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--config", a->config, "device config (YAML)")->capture_default_str();
  cmd->add_flag("--pty", a->pty, "serve on a new pseudo-terminal (the only transport for now)")
      ->required();
  cmd->add_option("--seconds", a->seconds, "stop after this long (0: until Ctrl-C)");
  cmd->add_option("--heartbeat-timeout", a->heartbeat_timeout,
                  "safe state when the host is silent this long [s]")
      ->capture_default_str();
  cmd->add_option("--seed", a->seed, "random seed of the simulated device")
      ->check(seed_check())
      ->capture_default_str();
  return [a] {
    require_range(a->seconds, 0, 86400, "--seconds", "s");
    if (const Status v = device::validate(device::DeviceEmulatorOptions{a->heartbeat_timeout}); !v)
      throw UsageError("--heartbeat-timeout: " + v.error().message);
    const auto cfg = strings::load_device_config(resolve_data_path(a->config));
    auto sim = make_simulated(cfg, a->seed);
    if (auto st = sim->open(); !st.ok()) throw UsageError(st.error().message);
    auto pty = device::open_pty();
    if (!pty) throw UsageError(pty.error().message);
    device::DeviceEmulator emulator(*sim, pty->master_fd, {a->heartbeat_timeout});
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::cout << pty->slave_path << std::endl;  // the one line a script reads
    std::cerr << "emulate-device: " << sim->info().name << " (" << sim->info().string_count
              << " strings) on " << pty->slave_path << "; Ctrl-C to stop\n";
    std::thread timer;
    if (a->seconds > 0) {
      timer = std::thread([s = a->seconds] {
        const auto end = core::monotonic_ns() + core::s_to_ns(s);
        while (!g_stop.load() && core::monotonic_ns() < end) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        g_stop.store(true);
      });
    }
    // The emulator stands in for a microcontroller: real-time priority, on the first CPU (the
    // servo loop pins itself to the last).
    if (const Status rt = core::set_fifo_priority(70); !rt.ok()) {
      std::cerr << "emulate-device: warning: " << rt.error().message << "; expect latency spikes\n";
    }
    (void)core::pin_to_cpu(0);
    emulator.run(g_stop);
    if (timer.joinable()) timer.join();
    const auto c = emulator.counters();
    std::cerr << "emulate-device: " << c.frames_in << " frames in, " << c.frames_out
              << " out, " << c.rejected << " rejected, " << c.watchdog_trips
              << " watchdog trips, " << c.io_errors << " I/O errors, decoder errors: "
              << c.decoder.bad_crc << " CRC, " << c.decoder.bad_length << " length\n";
    sim->close();
    ::close(pty->master_fd);
    return 0;
  };
}

}  // namespace spidar::app
