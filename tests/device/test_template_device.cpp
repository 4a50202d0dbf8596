#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "device_test_support.hpp"
#include "spidar/device/servo_loop.hpp"

namespace spidar::device {
std::unique_ptr<Device> make_template_device(int string_count);

namespace {

TEST(TemplateDevice, DrivesTheServoLoopAsIs) {
  auto dev = make_template_device(24);
  ASSERT_TRUE(dev->open().ok());
  ServoConfig cfg;
  // A number of cycles, not a time (a sanitizer build may cycle slowly); late wake-ups are not
  // what this tests.
  cfg.deadline_periods = 1000;
  cfg.stall_limit_s = 1.0;
  ServoLoop loop(*dev, testing::spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (loop.cycles() <= 10 && loop.running() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  loop.stop();
  EXPECT_GT(loop.cycles(), 10u);
  EXPECT_EQ(loop.faults(), 0u);
  dev->close();
  EXPECT_FALSE(dev->status().open);
  EncoderReading r;
  EXPECT_FALSE(dev->read(r).ok());
}

}  // namespace
}  // namespace spidar::device
