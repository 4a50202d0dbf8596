// Wire protocol: CRC check value, exact byte layout, round trips for every frame type.
#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "spidar/device/protocol.hpp"

namespace spidar::device::protocol {
namespace {

std::vector<Frame> decode_all(std::span<const std::uint8_t> bytes, FrameDecoder* dec_out = nullptr) {
  FrameDecoder dec;
  std::vector<Frame> frames;
  dec.feed(bytes, [&](const Frame& f) { frames.push_back(f); });
  if (dec_out) *dec_out = dec;
  return frames;
}

TEST(Protocol, Crc16CcittFalseCheckValue) {
  constexpr std::string_view s = "123456789";
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(crc16({p, s.size()}), 0x29B1);
  EXPECT_EQ(crc16({}), 0xFFFF);
  // Incremental use gives the same value.
  EXPECT_EQ(crc16({p + 4, 5}, crc16({p, 4})), 0x29B1);
}

TEST(Protocol, HeartbeatByteLayout) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(encode_heartbeat(buf, 0x42), 7u);
  EXPECT_EQ(buf[0], 0xA5);
  EXPECT_EQ(buf[1], 0x5A);
  EXPECT_EQ(buf[2], 0);     // len
  EXPECT_EQ(buf[3], 0x03);  // type
  EXPECT_EQ(buf[4], 0x42);  // seq
  const std::uint16_t crc = crc16({buf.data() + 2, 3});
  EXPECT_EQ(buf[5], crc & 0xFF);  // CRC low byte first
  EXPECT_EQ(buf[6], crc >> 8);
}

TEST(Protocol, LittleEndianFields) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  ASSERT_EQ(encode_set_limits(buf, 1, {-2, 0x1234}), 11u);
  EXPECT_EQ(buf[5], 0xFE);
  EXPECT_EQ(buf[6], 0xFF);
  EXPECT_EQ(buf[7], 0x34);
  EXPECT_EQ(buf[8], 0x12);
  Counts c;
  c.device_time_us = 0x01020304;
  c.status_flags = kFaultWatchdog;
  c.count = 1;
  c.counts[0] = -1;
  ASSERT_EQ(encode_counts(buf, 9, c), frame_size(12));
  EXPECT_EQ(buf[2], 12);
  EXPECT_EQ(buf[3], 0x81);
  EXPECT_EQ(buf[5], 0x04);
  EXPECT_EQ(buf[8], 0x01);
  EXPECT_EQ(buf[9], kFaultWatchdog);
  for (int i = 13; i < 17; ++i) EXPECT_EQ(buf[i], 0xFF);
}

TEST(Protocol, SetCommandsRoundTrip) {
  for (int n : {0, 1, 8, 24, kMaxDeviceStrings}) {
    std::vector<std::int16_t> cmd(n);
    for (int i = 0; i < n; ++i) cmd[i] = static_cast<std::int16_t>(i * 2731 - 32768);
    if (n > 1) cmd[1] = 32767;
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    const std::size_t len = encode_set_commands(buf, static_cast<std::uint8_t>(n), cmd);
    ASSERT_EQ(len, frame_size(set_commands_payload(n)));
    const auto frames = decode_all({buf.data(), len});
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0].type, FrameType::kSetCommands);
    EXPECT_EQ(frames[0].seq, n);
    SetCommands m;
    ASSERT_TRUE(parse(frames[0], m));
    ASSERT_EQ(m.count, n);
    for (int i = 0; i < n; ++i) EXPECT_EQ(m.commands[i], cmd[i]) << "string " << i;
  }
}

TEST(Protocol, SetLimitsRoundTrip) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const std::size_t len = encode_set_limits(buf, 200, {-32768, 32767});
  const auto frames = decode_all({buf.data(), len});
  ASSERT_EQ(frames.size(), 1u);
  SetLimits m;
  ASSERT_TRUE(parse(frames[0], m));
  EXPECT_EQ(frames[0].seq, 200);
  EXPECT_EQ(m.command_min, -32768);
  EXPECT_EQ(m.command_max, 32767);
  Counts wrong;
  EXPECT_FALSE(parse(frames[0], wrong));
}

TEST(Protocol, HeartbeatRoundTrip) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const std::size_t len = encode_heartbeat(buf, 255);
  const auto frames = decode_all({buf.data(), len});
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].type, FrameType::kHeartbeat);
  EXPECT_EQ(frames[0].seq, 255);
  EXPECT_EQ(frames[0].payload_size, 0);
}

TEST(Protocol, ZeroCountersRoundTrip) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const std::size_t len = encode_zero_counters(buf, 3, {0x80000005u});
  const auto frames = decode_all({buf.data(), len});
  ASSERT_EQ(frames.size(), 1u);
  ZeroCounters m;
  ASSERT_TRUE(parse(frames[0], m));
  EXPECT_EQ(m.mask, 0x80000005u);
}

TEST(Protocol, CountsRoundTrip) {
  for (int n : {0, 3, 24, kMaxDeviceStrings}) {
    Counts c;
    c.device_time_us = 0xFFFFFFF0u;
    c.status_flags = kFaultOverCurrent | kFaultWatchdog;
    c.count = n;
    for (int i = 0; i < n; ++i) c.counts[i] = (i % 2 ? -1 : 1) * (i * 123457 + 8388607 * (i == 5));
    std::array<std::uint8_t, kMaxFrameSize> buf{};
    const std::size_t len = encode_counts(buf, 17, c);
    ASSERT_EQ(len, frame_size(counts_payload(n)));
    const auto frames = decode_all({buf.data(), len});
    ASSERT_EQ(frames.size(), 1u);
    Counts m;
    ASSERT_TRUE(parse(frames[0], m));
    EXPECT_EQ(m.device_time_us, c.device_time_us);
    EXPECT_EQ(m.status_flags, c.status_flags);
    ASSERT_EQ(m.count, n);
    for (int i = 0; i < n; ++i) EXPECT_EQ(m.counts[i], c.counts[i]) << "string " << i;
  }
}

TEST(Protocol, FrameSizesForSpidar8) {
  // 24 strings: what docs/protocol.md's bandwidth table is based on.
  EXPECT_EQ(frame_size(set_commands_payload(24)), 55u);
  EXPECT_EQ(frame_size(counts_payload(24)), 111u);
  EXPECT_EQ(kMaxFrameSize, 143u);
}

TEST(Protocol, EncodeRefusesWhatDoesNotFit) {
  std::array<std::uint8_t, 10> small{};
  EXPECT_EQ(encode_heartbeat(small, 0), 7u);
  EXPECT_EQ(encode_set_limits(small, 0, {}), 0u);  // needs 11 bytes
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  std::vector<std::int16_t> too_many(kMaxDeviceStrings + 1);
  EXPECT_EQ(encode_set_commands(buf, 0, too_many), 0u);
  Counts c;
  c.count = kMaxDeviceStrings + 1;
  EXPECT_EQ(encode_counts(buf, 0, c), 0u);
  c.count = -1;
  EXPECT_EQ(encode_counts(buf, 0, c), 0u);
  std::array<std::uint8_t, kMaxPayload + 1> big{};
  EXPECT_EQ(encode_frame(buf, FrameType::kCounts, 0, big), 0u);
}

TEST(Protocol, ValidLengths) {
  EXPECT_TRUE(valid_length(0x01, 48));
  EXPECT_FALSE(valid_length(0x01, 47));
  EXPECT_FALSE(valid_length(0x01, 66));
  EXPECT_TRUE(valid_length(0x02, 4));
  EXPECT_FALSE(valid_length(0x03, 1));
  EXPECT_TRUE(valid_length(0x81, 8));
  EXPECT_FALSE(valid_length(0x81, 7));
  EXPECT_FALSE(valid_length(0x81, 10));
  EXPECT_FALSE(valid_length(0x05, 0));
  EXPECT_STREQ(type_name(FrameType::kCounts), "counts");
}

}  // namespace
}  // namespace spidar::device::protocol
