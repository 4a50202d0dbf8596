// Faults of the serial path through a pseudo-terminal: the port is held exclusively, the baud
// rate must carry the servo rate, the device's heartbeat timeout is bounded, and status bits the
// device reports reach the servo loop's safe state.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <string>

#include "device_test_support.hpp"
#include "pty_link.hpp"
#include "spidar/device/link_budget.hpp"
#include "spidar/device/servo_loop.hpp"

namespace spidar::device {
namespace {

using testing::PtyLink;
using testing::contains;
using testing::Pushing;


std::int32_t largest(const std::vector<std::int32_t>& v) {
  return v.empty() ? std::numeric_limits<std::int32_t>::min()
                   : *std::max_element(v.begin(), v.end());
}

TEST(SerialExclusive, ASecondOpenOfTheSamePortIsRefused) {
  Result<PtyPair> pty = open_pty();
  ASSERT_TRUE(pty.ok()) << pty.error().message;
  Result<SerialPort> opened = SerialPort::open(pty->slave_path, 921600);
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  SerialPort first = std::move(opened).value();
  Result<SerialPort> second = SerialPort::open(pty->slave_path, 921600);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().message,
            "serial port " + pty->slave_path +
                ": in use by another process (it holds the port exclusively; close it first)");
  // The first holder is unaffected by the refused open, and once it lets go the port is free.
  const std::array<std::uint8_t, 3> abc{'a', 'b', 'c'};
  EXPECT_EQ(first.write_all(abc, 1.0).status, IoStatus::kOk);
  first.close();
  Result<SerialPort> third = SerialPort::open(pty->slave_path, 921600);
  EXPECT_TRUE(third.ok()) << third.error().message;
  ::close(pty->master_fd);
}

TEST(SerialExclusive, ASecondSerialDeviceOnTheSamePortFailsToOpen) {
  PtyLink link(4);
  link.start_emulator();
  SerialDevice first(link.config(4));
  ASSERT_TRUE(first.open().ok());
  SerialDevice second(link.config(4));
  const Status s = second.open();
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, link.slave_path + ": in use by another process"))
      << s.error().message;
  EXPECT_FALSE(second.status().open);
  // The first device still works.
  EncoderReading r;
  EXPECT_TRUE(first.read(r).ok());
  first.close();
  EXPECT_TRUE(second.open().ok());
}

TEST(LinkBudget, BytesPerCycleAreRequestPlusAnswer) {
  EXPECT_EQ(link_bytes_per_cycle(24), 55u + 111u);  // docs/protocol.md's table
  EXPECT_EQ(link_bytes_per_cycle(8), 23u + 47u);
  EXPECT_DOUBLE_EQ(min_baud(24, 1000.0), 1'660'000.0);
  EXPECT_NEAR(max_rate_hz(921600, 24), 555.2, 0.1);
  EXPECT_TRUE(check_link_budget("port", 921600, 8, 1000.0).ok());  // 700 000 baud needed
  EXPECT_TRUE(check_link_budget("port", 2000000, 24, 1000.0).ok());
  const Status s = check_link_budget("serial /dev/ttyUSB0", 921600, 24, 1000.0);
  ASSERT_FALSE(s.ok());
  const std::string& m = s.error().message;
  EXPECT_TRUE(contains(m, "serial /dev/ttyUSB0: 921600 baud cannot carry 24 strings at 1000 Hz"))
      << m;
  EXPECT_TRUE(contains(m, "needs at least 1660000 baud")) << m;
  EXPECT_TRUE(contains(m, "the smallest standard rate that is enough is 2000000 baud")) << m;
  EXPECT_TRUE(contains(m, "carries at most 555 Hz")) << m;
  const Status beyond = check_link_budget("port", 4000000, 24, 4000.0);
  ASSERT_FALSE(beyond.ok());
  EXPECT_TRUE(contains(beyond.error().message, "no standard rate is enough"))
      << beyond.error().message;
}

TEST(LinkBudget, TheServoLoopRefusesARateTheBaudRateCannotCarry) {
  const strings::DeviceConfig& cfg = testing::spidar8();
  PtyLink link(cfg.string_count());
  link.start_emulator();
  SerialDeviceConfig c = link.config(cfg.string_count());
  c.baud = 921600;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  ServoConfig servo;
  servo.rate_hz = 1000;
  {
    ServoLoop loop(dev, cfg, servo, std::make_shared<ZeroForce>());
    const Status s = loop.start();
    ASSERT_FALSE(s.ok());
    const std::string& m = s.error().message;
    EXPECT_TRUE(contains(
        m, "serial " + link.slave_path + ": 921600 baud cannot carry 24 strings at 1000 Hz"))
        << m;
    EXPECT_TRUE(contains(m, "1660000 baud")) << m;
    EXPECT_FALSE(loop.running());
  }
  EXPECT_TRUE(dev.check_rate(500).ok());  // 830 000 baud: fits
  dev.close();

  c.check_link_budget = false;  // e.g. a pty standing in for a faster transport
  SerialDevice unchecked(c);
  ASSERT_TRUE(unchecked.open().ok());
  EXPECT_TRUE(unchecked.check_rate(1000).ok());
}

// The servo thread waits up to read_timeout_s for room to write: at most a second; and a timeout
// shorter than two servo periods would lose the device on any late reading.
TEST(SerialReadTimeout, IsBoundedAndAtLeastTwoPeriods) {
  SerialDeviceConfig c;
  c.port = "/nonexistent/tty";
  c.string_count = 24;
  c.read_timeout_s = 5.0;
  SerialDevice slow(c);
  const Status s = slow.open();
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "read_timeout_s 5 s out of range (expected more than 0 and at most 1 s)"))
      << s.error().message;
  c.read_timeout_s = 0.001;
  c.check_link_budget = false;
  SerialDevice fast(c);
  const Status r = fast.check_rate(1000);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.error().message, "read_timeout_s 0.001 s is shorter than two servo periods at 1000 Hz (0.002 s)"))
      << r.error().message;
  EXPECT_TRUE(fast.check_rate(2000).ok());  // two periods of 0.5 ms fit into 1 ms
}

TEST(HeartbeatTimeout, IsBoundedToOneSecond) {
  EXPECT_TRUE(validate(DeviceEmulatorOptions{0.1}).ok());
  EXPECT_TRUE(validate(DeviceEmulatorOptions{kMaxHeartbeatTimeoutS}).ok());
  for (const double bad : {1e9, 1.5, 0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    const Status s = validate(DeviceEmulatorOptions{bad});
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_TRUE(contains(s.error().message, "heartbeat timeout")) << s.error().message;
    EXPECT_TRUE(contains(s.error().message, "expected > 0 and <= 1 s")) << s.error().message;
  }
  testing::FakeDevice fake(2);
  EXPECT_THROW(DeviceEmulator(fake, -1, DeviceEmulatorOptions{1e9}), SpidarError);
}

TEST(SerialServoFaults, OverCurrentReportedByTheDeviceTripsTheSafeState) {
  const strings::DeviceConfig& cfg = testing::spidar8();
  PtyLink link(cfg.string_count());
  link.start_emulator();
  SerialDeviceConfig c = link.config(cfg.string_count());
  c.baud = 2000000;
  c.reply_wait_s = 0.0;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  ServoConfig servo;
  servo.rate_hz = 1000;
  servo.realtime = false;
  servo.max_repeated_readings = 1'000'000;  // a loaded pty may hold answers back; not tested here
  servo.force_timeout_s = 1e3;
  servo.deadline_periods = 1e6;
  servo.stall_limit_s = 1.0;
  ServoLoop loop(dev, cfg, servo, std::make_shared<Pushing>());
  ASSERT_TRUE(loop.start().ok());
  ASSERT_TRUE(PtyLink::wait_until([&] { return loop.cycles() >= 30 || !loop.running(); }, 30.0));
  EXPECT_EQ(loop.faults(), 0u) << loop.fault_message();
  EXPECT_TRUE(
      PtyLink::wait_until([&] { return largest(link.fake.last_commands()) > c.command_min; }, 30.0))
      << "forces displayed before the fault";
  link.fake.set_flags(kFaultOverCurrent);
  EXPECT_TRUE(PtyLink::wait_until([&] { return (loop.faults() & kFaultOverCurrent) != 0; }, 30.0));
  const std::uint64_t latched_by = loop.cycles();
  ASSERT_TRUE(PtyLink::wait_until([&] { return loop.cycles() >= latched_by + 5; }, 30.0));
  loop.stop();
  const ServoStats s = loop.stats();
  EXPECT_TRUE(s.faults & kFaultOverCurrent) << fault_names(s.faults);
  EXPECT_TRUE(
      contains(s.fault_message, "over_current: the device reports a motor over its current limit"))
      << s.fault_message;
  // Latched: the newest sample still carries it and displays no force; the motors got minimums.
  FingertipSample newest;
  ASSERT_EQ(loop.newest_samples(&newest, 1), 1u);
  EXPECT_TRUE(newest.faults & kFaultOverCurrent);
  for (int f = 0; f < newest.finger_count; ++f) EXPECT_EQ(newest.f_W[f][2], 0.0) << f;
  EXPECT_TRUE(PtyLink::wait_until(
      [&] { return largest(link.fake.last_commands()) == c.command_min; }, 30.0));
}

}  // namespace
}  // namespace spidar::device
