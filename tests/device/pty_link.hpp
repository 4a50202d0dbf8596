#pragma once
/// Test fixture: a pty pair, a DeviceEmulator on the master (own thread) backed by a FakeDevice,
/// and a SerialDevice on the slave.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include "fake_device.hpp"
#include "spidar/device/device_emulator.hpp"
#include "spidar/device/serial_device.hpp"
#include "spidar/device/serial_port.hpp"

namespace spidar::device::testing {

/// Generous timeouts: the machine is shared and sanitizer builds are slow; tests assert
/// behaviour, not timing.
inline constexpr double kTestReadTimeout = 1.0;

class PtyLink {
 public:
  explicit PtyLink(int strings = 24, DeviceEmulatorOptions opts = {0.5},
                   std::int32_t backend_min = 0, std::int32_t backend_max = 4095)
      : fake(strings, backend_min, backend_max) {
    Result<PtyPair> pty = open_pty();
    if (!pty) throw SpidarError(pty.error().message);
    master_fd = pty->master_fd;
    slave_path = pty->slave_path;
    (void)fake.open();
    emulator = std::make_unique<DeviceEmulator>(fake, master_fd, opts);
  }
  ~PtyLink() {
    stop_emulator();
    close_master();
  }

  SerialDeviceConfig config(int strings = 24) const {
    SerialDeviceConfig c;
    c.port = slave_path;
    c.string_count = strings;
    c.read_timeout_s = kTestReadTimeout;
    c.reply_wait_s = kTestReadTimeout;  // a strict exchange: a read returns the answer to the write
    return c;
  }

  void start_emulator() {
    stop = false;
    thread = std::thread([this] { emulator->run(stop); });
  }
  void stop_emulator() {
    stop = true;
    if (thread.joinable()) thread.join();
  }
  void close_master() {
    if (master_fd >= 0) ::close(master_fd);
    master_fd = -1;
  }

  /// Waits up to `timeout_s` for `pred`; true if it became true.
  template <typename Pred>
  static bool wait_until(Pred pred, double timeout_s = 5.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      if (pred()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return pred();
  }

  FakeDevice fake;
  int master_fd = -1;
  std::string slave_path;
  std::unique_ptr<DeviceEmulator> emulator;
  std::atomic<bool> stop{false};
  std::thread thread;
};

}  // namespace spidar::device::testing
