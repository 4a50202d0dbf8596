// The serial path end to end through a pseudo-terminal: SerialDevice (host) ↔ DeviceEmulator
// (device, own thread) ↔ FakeDevice.
#include <gtest/gtest.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "device_test_support.hpp"
#include "pty_link.hpp"

namespace spidar::device {
namespace {

using testing::contains;

using testing::PtyLink;

std::array<std::int32_t, kMaxDeviceStrings> ramp(std::int32_t base) {
  std::array<std::int32_t, kMaxDeviceStrings> c{};
  for (int i = 0; i < kMaxDeviceStrings; ++i) c[i] = base + (i % 2 ? -1 : 1) * i * 1001;
  return c;
}

TEST(SerialPort, OpenMissingPathNamesPathAndErrno) {
  Result<SerialPort> p = SerialPort::open("/dev/does-not-exist-spidar", 115200);
  ASSERT_FALSE(p.ok());
  EXPECT_TRUE(contains(p.error().message, "/dev/does-not-exist-spidar")) << p.error().message;
  EXPECT_TRUE(contains(p.error().message, "No such file or directory")) << p.error().message;
}

TEST(SerialPort, UnsupportedBaudRateIsAnError) {
  Result<PtyPair> pty = open_pty();
  ASSERT_TRUE(pty.ok()) << pty.error().message;
  Result<SerialPort> p = SerialPort::open(pty->slave_path, 12345);
  ASSERT_FALSE(p.ok());
  EXPECT_TRUE(contains(p.error().message, "unsupported baud rate 12345")) << p.error().message;
  EXPECT_TRUE(contains(p.error().message, pty->slave_path)) << p.error().message;
  EXPECT_EQ(baud_to_speed(921600), static_cast<unsigned>(B921600));
  ::close(pty->master_fd);
}

TEST(SerialPort, NotATerminalIsAnError) {
  const std::string path = ::testing::TempDir() + "spidar_not_a_tty";
  std::ofstream(path) << "x";
  Result<SerialPort> p = SerialPort::open(path, 115200);
  ASSERT_FALSE(p.ok());
  EXPECT_TRUE(contains(p.error().message, "not a terminal")) << p.error().message;
  std::remove(path.c_str());
}

TEST(SerialPort, PtyCarriesRawBytesBothWays) {
  Result<PtyPair> pty = open_pty();
  ASSERT_TRUE(pty.ok()) << pty.error().message;
  Result<SerialPort> opened = SerialPort::open(pty->slave_path, 921600);
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  SerialPort port = std::move(opened).value();
  // Every byte value, including the ones a cooked tty would translate (CR, LF, ^C, ^S, DEL).
  std::array<std::uint8_t, 256> all{};
  for (int i = 0; i < 256; ++i) all[i] = static_cast<std::uint8_t>(i);
  ASSERT_EQ(write_all(pty->master_fd, all, 1.0).status, IoStatus::kOk);
  std::array<std::uint8_t, 256> got{};
  std::size_t n = 0;
  while (n < got.size()) {
    const IoResult r = port.read_some(std::span(got).subspan(n), 1.0);
    ASSERT_EQ(r.status, IoStatus::kOk);
    n += r.bytes;
  }
  EXPECT_EQ(got, all);
  ASSERT_EQ(port.write_all(all, 1.0).status, IoStatus::kOk);
  n = 0;
  while (n < got.size()) {
    const IoResult r = read_some(pty->master_fd, std::span(got).subspan(n), 1.0);
    ASSERT_EQ(r.status, IoStatus::kOk);
    n += r.bytes;
  }
  EXPECT_EQ(got, all);
  // Nothing more: a read times out.
  EXPECT_EQ(port.read_some(got, 0.01).status, IoStatus::kTimeout);
  ::close(pty->master_fd);
}

TEST(SerialPort, ReadReadyTakesWhatIsThereAndSeesTheHangUp) {
  Result<PtyPair> pty = open_pty();
  ASSERT_TRUE(pty.ok()) << pty.error().message;
  Result<SerialPort> opened = SerialPort::open(pty->slave_path, 921600);
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  SerialPort port = std::move(opened).value();
  std::array<std::uint8_t, 64> got{};
  IoResult r = port.read_ready(got);  // nothing sent: returns at once, nothing read
  EXPECT_EQ(r.status, IoStatus::kOk);
  EXPECT_EQ(r.bytes, 0u);
  const std::array<std::uint8_t, 5> hello{'h', 'e', 'l', 'l', 'o'};
  ASSERT_EQ(write_all(pty->master_fd, hello, 1.0).status, IoStatus::kOk);
  std::size_t n = 0;
  ASSERT_TRUE(PtyLink::wait_until([&] {
    r = port.read_ready(std::span(got).subspan(n));
    n += r.bytes;
    return r.status != IoStatus::kOk || n >= hello.size();
  }));
  ASSERT_EQ(r.status, IoStatus::kOk);
  ASSERT_EQ(n, hello.size());
  EXPECT_TRUE(std::equal(hello.begin(), hello.end(), got.begin()));
  ::close(pty->master_fd);  // the device side goes away: the slave is hung up
  r = port.read_ready(got);
  EXPECT_EQ(r.status, IoStatus::kClosed);
}

TEST(SerialDevice, BadConfigurationIsAnErrorOnOpen) {
  SerialDeviceConfig c;
  c.port = "/dev/null";
  c.string_count = 0;
  SerialDevice d0(c);
  Status s = d0.open();
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "string_count 0")) << s.error().message;
  c.string_count = 24;
  c.command_min = 10;
  c.command_max = 5;
  SerialDevice d1(c);
  s = d1.open();
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "command_min 10 > command_max 5")) << s.error().message;
}

TEST(SerialDevice, CountsAndCommandsArrive) {
  PtyLink link;
  link.fake.set_counts(ramp(-8000000));
  link.start_emulator();
  SerialDevice dev(link.config());
  ASSERT_TRUE(dev.open().ok());
  EXPECT_TRUE(dev.status().open);
  EXPECT_EQ(dev.info().string_count, 24);

  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());  // answers open()'s heartbeat
  EXPECT_EQ(r.string_count, 24);
  const auto expected = ramp(-8000000);
  for (int i = 0; i < 24; ++i) EXPECT_EQ(r.counts[i], expected[i]) << "string " << i;
  EXPECT_GT(r.host_time_ns, 0);

  std::uint32_t last_time = r.device_time_us;
  for (int cycle = 0; cycle < 20; ++cycle) {
    std::array<std::int32_t, 24> cmd{};
    for (int i = 0; i < 24; ++i) cmd[i] = 100 * cycle + i;
    link.fake.set_counts(ramp(cycle));
    ASSERT_TRUE(dev.write(cmd).ok());
    ASSERT_TRUE(dev.read(r).ok());  // the answer to this write: counts sampled after it
    EXPECT_EQ(r.counts[3], ramp(cycle)[3]);
    EXPECT_GE(r.device_time_us, last_time);
    last_time = r.device_time_us;
    const auto got = link.fake.last_commands();
    ASSERT_EQ(got.size(), 24u);
    for (int i = 0; i < 24; ++i) EXPECT_EQ(got[i], cmd[i]);
  }
  // Two reads in a row: the second polls with a heartbeat.
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(dev.status().faults, kFaultNone);
  const SerialLinkStats st = dev.link_stats();
  EXPECT_EQ(st.counts_in, 22u);
  EXPECT_EQ(st.decoder.errors(), 0u);
  EXPECT_EQ(st.stale, 0u);
  dev.close();
  EXPECT_FALSE(dev.status().open);
  link.stop_emulator();
  const EmulatorCounters ec = link.emulator->counters();
  EXPECT_EQ(ec.decoder.errors(), 0u);
  EXPECT_EQ(ec.rejected, 0u);
  EXPECT_GE(ec.frames_out, 22u);  // + the answer to close()'s minimum commands, if it got there
  EXPECT_LE(ec.frames_out, 23u);
  EXPECT_GE(ec.frames_in, 23u);  // limits, 2 heartbeats, 20 commands (+ close()'s minimums)
}

TEST(SerialDevice, WrongCommandCountIsAnError) {
  PtyLink link;
  link.start_emulator();
  SerialDevice dev(link.config());
  ASSERT_TRUE(dev.open().ok());
  std::array<std::int32_t, 3> cmd{};
  Status s = dev.write(cmd);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "3 commands given")) << s.error().message;
}

TEST(SerialDevice, CommandsAreClampedToLimits) {
  PtyLink link(4);
  link.start_emulator();
  SerialDeviceConfig c = link.config(4);
  c.command_min = 100;
  c.command_max = 2000;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  const std::array<std::int32_t, 4> cmd{-5, 50000, 1000, std::numeric_limits<std::int32_t>::min()};
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(link.fake.last_commands(), (std::vector<std::int32_t>{100, 2000, 1000, 100}));
}

TEST(SerialDevice, CommandsAreClampedToInt16OnTheWire) {
  PtyLink link(3, {0.5}, -100000, 100000);
  link.start_emulator();
  SerialDeviceConfig c = link.config(3);
  c.command_min = -40000;
  c.command_max = 40000;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  const std::array<std::int32_t, 3> cmd{-39000, 39000, -7};
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(link.fake.last_commands(), (std::vector<std::int32_t>{-32768, 32767, -7}));
}

TEST(SerialDevice, EmulatorEnforcesHostLimitsToo) {
  // The firmware clamps with the limits the host sent, whatever arrives in SetCommands.
  PtyLink link(2);
  link.start_emulator();
  SerialDeviceConfig c = link.config(2);
  c.command_min = 10;
  c.command_max = 20;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  // Bypass the host's clamping: a raw SetCommands frame, on the port the host has let go of (it
  // holds it exclusively while open; its close() sends minimums, 10 and 10, first).
  dev.close();
  Result<SerialPort> raw = SerialPort::open(link.slave_path, 921600);
  ASSERT_TRUE(raw.ok()) << raw.error().message;
  std::array<std::uint8_t, protocol::kMaxFrameSize> buf{};
  const std::array<std::int16_t, 2> wild{-1000, 30000};
  const std::size_t n = protocol::encode_set_commands(buf, 77, wild);
  ASSERT_EQ(write_all(raw->fd(), {buf.data(), n}, 1.0).status, IoStatus::kOk);
  ASSERT_TRUE(PtyLink::wait_until(
      [&] { return link.fake.last_commands() == std::vector<std::int32_t>{10, 20}; }));
  EXPECT_EQ(link.fake.last_commands(), (std::vector<std::int32_t>{10, 20}));
}

TEST(SerialDevice, SafeStateRequestFromAnotherThreadSendsMinimums) {
  PtyLink link(4);
  link.start_emulator();
  SerialDeviceConfig c = link.config(4);
  c.command_min = 50;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  std::thread other([&dev] { dev.request_safe_state(); });
  other.join();
  const std::array<std::int32_t, 4> cmd{1000, 2000, 3000, 4000};
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(link.fake.last_commands(), (std::vector<std::int32_t>{50, 50, 50, 50}));
  dev.clear_safe_state();
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(link.fake.last_commands(), (std::vector<std::int32_t>{1000, 2000, 3000, 4000}));
}

TEST(SerialDevice, HeartbeatTimeoutPutsBackendInSafeState) {
  // A timeout well above a loaded machine's pauses between the host's frames below (at 0.1 s a
  // pause of the test's thread could trip it early, twice).
  PtyLink link(4, {0.5});
  link.start_emulator();
  SerialDevice dev(link.config(4));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(r.status_flags & kFaultWatchdog, 0u);
  const std::array<std::int32_t, 4> cmd{500, 500, 500, 500};
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_FALSE(link.fake.safe());

  // The host goes quiet: within the heartbeat timeout (plus scheduling slack) the firmware trips.
  ASSERT_TRUE(PtyLink::wait_until([&] { return link.fake.safe(); }, 10.0));
  EXPECT_TRUE(link.emulator->watchdog_tripped());
  EXPECT_EQ(link.emulator->counters().watchdog_trips, 1u);

  // A heartbeat feeds the watchdog but the safe state stays until commands resume.
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_NE(r.status_flags & kFaultWatchdog, 0u);
  EXPECT_TRUE(link.fake.safe());
  // The device's watchdog flag is reported per reading, not latched by the host.
  EXPECT_EQ(dev.status().faults & kFaultWatchdog, 0u);

  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(r.status_flags & kFaultWatchdog, 0u);
  EXPECT_FALSE(link.fake.safe());
  EXPECT_FALSE(link.emulator->watchdog_tripped());
}

TEST(SerialDevice, ZeroCountersOffsetsAndWraps) {
  PtyLink link(3);
  std::array<std::int32_t, kMaxDeviceStrings> c{};
  c[0] = 1000;
  c[1] = -8388608;  // most negative 24-bit count
  c[2] = 77;
  link.fake.set_counts(c);
  link.start_emulator();
  SerialDevice dev(link.config(3));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  ASSERT_TRUE(dev.zero_counters(0b011).ok());
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(r.counts[0], 0);
  EXPECT_EQ(r.counts[1], 0);
  EXPECT_EQ(r.counts[2], 77);
  c[0] = 900;
  c[1] = 8388607;  // one count below the zero, across the wrap
  link.fake.set_counts(c);
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_EQ(r.counts[0], -100);
  EXPECT_EQ(r.counts[1], -1);
}

TEST(SerialDevice, DeviceFaultFlagsAreReportedAndLatched) {
  PtyLink link(2);
  link.fake.set_flags(kFaultOverCurrent);
  link.start_emulator();
  SerialDevice dev(link.config(2));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  EXPECT_NE(r.status_flags & kFaultOverCurrent, 0u);
  EXPECT_NE(dev.status().faults & kFaultOverCurrent, 0u);
}

TEST(SerialDevice, StringCountMismatchIsAProtocolFault) {
  PtyLink link(24);
  link.start_emulator();
  SerialDevice dev(link.config(8));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  Status s = dev.read(r);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "24 strings, expected string_count = 8"))
      << s.error().message;
  EXPECT_NE(dev.status().faults & kFaultProtocol, 0u);
  // The emulator refuses 8 commands for a 24-string backend, and applies nothing.
  const std::array<std::int32_t, 8> cmd{};
  ASSERT_TRUE(dev.write(cmd).ok());
  EXPECT_FALSE(dev.read(r).ok());
  link.stop_emulator();
  EXPECT_EQ(link.fake.writes(), 0);
  EXPECT_GE(link.emulator->counters().rejected, 1u);
}

TEST(SerialDevice, SilentDeviceIsAReadTimeout) {
  PtyLink link(4);  // emulator not running
  SerialDeviceConfig c = link.config(4);
  c.read_timeout_s = 0.05;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  const auto t0 = std::chrono::steady_clock::now();
  Status s = dev.read(r);
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.error().message, "read_timeout")) << s.error().message;
  EXPECT_NE(dev.status().faults & kFaultReadTimeout, 0u);
  EXPECT_EQ(dev.status().faults & kFaultDisconnected, 0u);
  EXPECT_LT(dt, 2.0);  // bounded, not hung
  // Once the device answers again, reads recover (the fault stays latched).
  link.start_emulator();
  EXPECT_TRUE(PtyLink::wait_until([&] { return dev.read(r).ok(); }));
  EXPECT_NE(dev.status().faults & kFaultReadTimeout, 0u);
}

/// Sends a Counts frame with sequence number `seq` from the device side of `link` (its emulator
/// stopped): a late or repeated answer the host did not expect.
void inject_counts(PtyLink& link, std::uint8_t seq, std::int32_t value, int strings) {
  protocol::Counts c;
  c.count = strings;
  for (int i = 0; i < strings; ++i) c.counts[i] = value;
  std::array<std::uint8_t, protocol::kMaxFrameSize> buf{};
  const std::size_t n = protocol::encode_counts(buf, seq, c);
  ASSERT_EQ(write_all(link.master_fd, {buf.data(), n}, 1.0).status, IoStatus::kOk);
}

TEST(SerialDevice, LateAnswersRepeatTheLastReadingThenTheNewestIsTaken) {
  PtyLink link(4);
  std::array<std::int32_t, kMaxDeviceStrings> first{};
  first.fill(111);
  link.fake.set_counts(first);
  link.start_emulator();
  SerialDeviceConfig c = link.config(4);
  c.reply_wait_s = 0.0;  // the servo setting: never wait for an answer
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());  // the first read waits for a reading
  EXPECT_EQ(r.repeats, 0u);
  EXPECT_EQ(r.counts[0], 111);
  const std::int64_t first_time = r.host_time_ns;

  // The device falls silent: reads return at once with the same reading, counted as repeats.
  link.stop_emulator();
  std::array<std::int32_t, kMaxDeviceStrings> second{};
  second.fill(222);
  link.fake.set_counts(second);
  const std::array<std::int32_t, 4> cmd{1, 2, 3, 4};
  for (std::uint32_t k = 1; k <= 3; ++k) {
    ASSERT_TRUE(dev.write(cmd).ok());
    ASSERT_TRUE(dev.read(r).ok());
    EXPECT_EQ(r.repeats, k);
    EXPECT_EQ(r.counts[0], 111);
    EXPECT_EQ(r.host_time_ns, first_time);
  }
  EXPECT_EQ(dev.link_stats().repeated, 3u);

  // It answers the three queued commands at once: reads take the newest answer that is there.
  link.start_emulator();
  ASSERT_TRUE(PtyLink::wait_until([&] {
    EXPECT_TRUE(dev.read(r).ok());
    return dev.link_stats().counts_in == 4;  // open()'s heartbeat and the three commands
  }));
  EXPECT_EQ(r.counts[0], 222);
  EXPECT_GT(r.host_time_ns, first_time);
  SerialLinkStats st = dev.link_stats();
  EXPECT_LE(st.behind, 2u);  // answers that came while a newer one was still on its way
  EXPECT_EQ(st.stale, 0u);
  EXPECT_EQ(st.timeouts, 0u);
  EXPECT_EQ(dev.status().faults, kFaultNone);

  // An answer to an older request than the reading held is dropped as stale.
  link.stop_emulator();
  inject_counts(link, /*seq=*/1, 999, 4);  // open()'s heartbeat had sequence number 1
  ASSERT_TRUE(dev.write(cmd).ok());
  ASSERT_TRUE(PtyLink::wait_until([&] {
    (void)dev.read(r);
    return dev.link_stats().stale == 1;
  }));
  EXPECT_EQ(r.counts[0], 222);
  EXPECT_GT(r.repeats, 0u);
  EXPECT_EQ(dev.link_stats().counts_in, 4u);
}

TEST(SerialDevice, SilenceAfterAReadingBecomesAReadTimeout) {
  PtyLink link(4);
  link.start_emulator();
  SerialDeviceConfig c = link.config(4);
  c.reply_wait_s = 0.0;
  // Long enough that the first reads after the emulator stops (its join alone takes about 11 ms,
  // more on a loaded machine or under a sanitizer) still come before the timeout.
  c.read_timeout_s = 0.5;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  link.stop_emulator();
  const std::array<std::int32_t, 4> cmd{};
  std::uint32_t repeats = 0;
  Status s = Ok{};
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < end) {
    ASSERT_TRUE(dev.write(cmd).ok());
    s = dev.read(r);
    if (!s.ok()) break;
    repeats = r.repeats;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(s.ok());
  EXPECT_GE(repeats, 1u);  // late answers first, then the timeout
  EXPECT_TRUE(contains(s.error().message, "no new Counts frame")) << s.error().message;
  EXPECT_NE(dev.status().faults & kFaultReadTimeout, 0u);
  EXPECT_EQ(dev.link_stats().timeouts, 1u);
  // The device answers again: reads recover (the fault stays latched).
  link.start_emulator();
  EXPECT_TRUE(PtyLink::wait_until([&] { return dev.read(r).ok() && r.repeats == 0; }));
  EXPECT_NE(dev.status().faults & kFaultReadTimeout, 0u);
}

TEST(SerialDevice, ClosingTheMasterSideReportsDisconnect) {
  PtyLink link(4);
  link.start_emulator();
  SerialDevice dev(link.config(4));
  ASSERT_TRUE(dev.open().ok());
  EncoderReading r;
  ASSERT_TRUE(dev.read(r).ok());
  const std::array<std::int32_t, 4> cmd{1, 2, 3, 4};
  // The device vanishes (cable pulled): its end of the line is closed.
  link.stop_emulator();
  link.close_master();
  const auto t0 = std::chrono::steady_clock::now();
  Status s = dev.read(r);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(dev.status().faults & kFaultDisconnected, 0u) << s.error().message;
  EXPECT_TRUE(contains(s.error().message, "disconnected")) << s.error().message;
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(dt, testing::kTestReadTimeout);  // noticed at once, not as a timeout
  // Further calls keep failing cleanly.
  EXPECT_FALSE(dev.write(cmd).ok());
  EXPECT_FALSE(dev.read(r).ok());
  dev.close();
  dev.close();  // idempotent
  EXPECT_FALSE(dev.status().open);
}

TEST(SerialDevice, CloseSendsMinimumCommands) {
  PtyLink link(3);
  link.start_emulator();
  SerialDeviceConfig c = link.config(3);
  c.command_min = 7;
  SerialDevice dev(c);
  ASSERT_TRUE(dev.open().ok());
  const std::array<std::int32_t, 3> cmd{100, 200, 300};
  ASSERT_TRUE(dev.write(cmd).ok());
  dev.close();
  ASSERT_TRUE(PtyLink::wait_until(
      [&] { return link.fake.last_commands() == std::vector<std::int32_t>{7, 7, 7}; }));
}

TEST(DeviceEmulator, CountsGarbageAndKeepsServing) {
  PtyLink link(2);
  link.start_emulator();
  Result<SerialPort> opened = SerialPort::open(link.slave_path, 921600);
  ASSERT_TRUE(opened.ok());
  SerialPort port = std::move(opened).value();
  std::array<std::uint8_t, 64> junk{};
  for (std::size_t i = 0; i < junk.size(); ++i) junk[i] = static_cast<std::uint8_t>(i * 37 + 0xA5);
  ASSERT_EQ(port.write_all(junk, 1.0).status, IoStatus::kOk);
  std::array<std::uint8_t, protocol::kMaxFrameSize> buf{};
  const std::size_t n = protocol::encode_heartbeat(buf, 9);
  ASSERT_EQ(port.write_all({buf.data(), n}, 1.0).status, IoStatus::kOk);
  protocol::FrameDecoder dec;
  int counts = 0;
  std::array<std::uint8_t, 256> rx{};
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (counts == 0 && std::chrono::steady_clock::now() < end) {
    const IoResult r = port.read_some(rx, 0.1);
    dec.feed({rx.data(), r.bytes}, [&](const protocol::Frame& f) {
      EXPECT_EQ(f.type, protocol::FrameType::kCounts);
      EXPECT_EQ(f.seq, 9);
      ++counts;
    });
  }
  EXPECT_EQ(counts, 1);
  link.stop_emulator();
  const EmulatorCounters ec = link.emulator->counters();
  EXPECT_GT(ec.decoder.discarded, 0u);
  EXPECT_EQ(ec.frames_in, 1u);
}

}  // namespace
}  // namespace spidar::device
