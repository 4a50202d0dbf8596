#include <gtest/gtest.h>

#include <memory>
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
  cfg.max_seconds = 0.1;
  ServoLoop loop(*dev, testing::spidar8(), cfg, std::make_shared<ZeroForce>());
  ASSERT_TRUE(loop.start().ok());
  loop.wait();
  EXPECT_GT(loop.cycles(), 10u);
  EXPECT_EQ(loop.faults(), 0u);
  dev->close();
  EXPECT_FALSE(dev->status().open);
  EncoderReading r;
  EXPECT_FALSE(dev->read(r).ok());
}

}  // namespace
}  // namespace spidar::device
