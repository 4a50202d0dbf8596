// Streaming decoder: resync after noise, arbitrary chunking, rejection and counting of errors.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "spidar/device/protocol.hpp"

namespace spidar::device::protocol {
namespace {

using Bytes = std::vector<std::uint8_t>;

void append_frame(Bytes& out, std::size_t n_written, const std::array<std::uint8_t, kMaxFrameSize>& buf) {
  out.insert(out.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n_written));
}

Bytes counts_frame(std::uint8_t seq, int n, std::int32_t base) {
  Counts c;
  c.device_time_us = seq * 1000u;
  c.count = n;
  for (int i = 0; i < n; ++i) c.counts[i] = base + i;
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  Bytes out;
  append_frame(out, encode_counts(buf, seq, c), buf);
  return out;
}

Bytes commands_frame(std::uint8_t seq, int n) {
  std::vector<std::int16_t> cmd(n);
  for (int i = 0; i < n; ++i) cmd[i] = static_cast<std::int16_t>(seq * 10 + i);
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  Bytes out;
  append_frame(out, encode_set_commands(buf, seq, cmd), buf);
  return out;
}

Bytes heartbeat_frame(std::uint8_t seq) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  Bytes out;
  append_frame(out, encode_heartbeat(buf, seq), buf);
  return out;
}

struct Decoded {
  std::vector<std::uint8_t> seqs;
  DecoderStats stats;
  std::size_t buffered = 0;
};

Decoded decode(const Bytes& bytes, std::size_t chunk = 0) {
  FrameDecoder dec;
  Decoded d;
  auto on = [&](const Frame& f) { d.seqs.push_back(f.seq); };
  if (chunk == 0) {
    dec.feed(bytes, on);
  } else {
    for (std::size_t i = 0; i < bytes.size(); i += chunk) {
      dec.feed(std::span<const std::uint8_t>(bytes).subspan(i, std::min(chunk, bytes.size() - i)), on);
    }
  }
  d.stats = dec.stats();
  d.buffered = dec.buffered();
  EXPECT_EQ(d.stats.bytes_in, d.stats.frame_bytes + d.stats.discarded + d.buffered);
  return d;
}

TEST(FrameDecoder, ResyncsAfterRandomGarbage) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255), len(0, 300);
  for (int trial = 0; trial < 50; ++trial) {
    Bytes stream;
    std::vector<std::uint8_t> expected;
    for (int k = 0; k < 20; ++k) {
      const int g = len(rng);
      for (int i = 0; i < g; ++i) stream.push_back(static_cast<std::uint8_t>(byte(rng)));
      // Sometimes garbage that looks like the start of a frame, right before a real one.
      if (k % 3 == 0) stream.insert(stream.end(), {kSync0, kSync1, 136, 0x81, 0x00});
      const auto seq = static_cast<std::uint8_t>(k);
      const Bytes f = (k % 3 == 1) ? commands_frame(seq, 24)
                                   : (k % 3 == 2 ? heartbeat_frame(seq) : counts_frame(seq, 24, k));
      stream.insert(stream.end(), f.begin(), f.end());
      expected.push_back(seq);
    }
    const Decoded d = decode(stream);
    EXPECT_EQ(d.seqs, expected) << "trial " << trial;
    EXPECT_GT(d.stats.discarded, 0u);
    EXPECT_EQ(d.buffered, 0u);
  }
}

TEST(FrameDecoder, SplitReadsAtEveryByteBoundary) {
  Bytes stream = counts_frame(1, 24, 100);
  const Bytes b = commands_frame(2, 24);
  const Bytes c = heartbeat_frame(3);
  stream.insert(stream.end(), b.begin(), b.end());
  stream.insert(stream.end(), c.begin(), c.end());
  const std::vector<std::uint8_t> expected{1, 2, 3};
  for (std::size_t split = 0; split <= stream.size(); ++split) {
    FrameDecoder dec;
    std::vector<std::uint8_t> seqs;
    auto on = [&](const Frame& f) { seqs.push_back(f.seq); };
    dec.feed(std::span<const std::uint8_t>(stream).first(split), on);
    dec.feed(std::span<const std::uint8_t>(stream).subspan(split), on);
    EXPECT_EQ(seqs, expected) << "split at " << split;
    EXPECT_EQ(dec.stats().errors(), 0u);
  }
  for (std::size_t chunk = 1; chunk <= 16; ++chunk) {
    EXPECT_EQ(decode(stream, chunk).seqs, expected) << "chunk " << chunk;
  }
}

TEST(FrameDecoder, RejectsAndCountsBadCrc) {
  Bytes bad = counts_frame(1, 24, 0);
  bad[20] ^= 0x10;  // payload bit flip
  Bytes stream = bad;
  const Bytes good = counts_frame(2, 24, 0);
  stream.insert(stream.end(), good.begin(), good.end());
  const Decoded d = decode(stream);
  EXPECT_EQ(d.seqs, std::vector<std::uint8_t>{2});
  EXPECT_EQ(d.stats.bad_crc, 1u);
  EXPECT_EQ(d.stats.frames, 1u);
  EXPECT_EQ(d.stats.discarded, bad.size());

  Bytes crc_flip = heartbeat_frame(9);
  crc_flip.back() ^= 0x01;
  EXPECT_EQ(decode(crc_flip).stats.bad_crc, 1u);
  EXPECT_TRUE(decode(crc_flip).seqs.empty());
}

TEST(FrameDecoder, RejectsAndCountsBadLengthAndType) {
  Bytes over = counts_frame(1, 24, 0);
  over[2] = static_cast<std::uint8_t>(kMaxPayload + 1);  // longer than any frame
  Decoded d = decode(over);
  EXPECT_EQ(d.stats.bad_length, 1u);
  EXPECT_EQ(d.stats.frames, 0u);

  Bytes odd = commands_frame(1, 4);
  odd[2] = 7;  // SetCommands must have an even length
  d = decode(odd);
  EXPECT_EQ(d.stats.bad_length, 1u);

  Bytes hb = heartbeat_frame(1);
  hb[2] = 4;  // heartbeat has no payload
  d = decode(hb);
  EXPECT_EQ(d.stats.bad_length, 1u);

  Bytes type = heartbeat_frame(1);
  type[3] = 0x7E;
  d = decode(type);
  EXPECT_EQ(d.stats.bad_type, 1u);
  EXPECT_EQ(d.stats.frames, 0u);

  // A bad header does not swallow the real frame behind it.
  Bytes stream{kSync0, kSync1, 0xFF, kSync0, kSync1, 4, 0x03};
  const Bytes good = heartbeat_frame(5);
  stream.insert(stream.end(), good.begin(), good.end());
  d = decode(stream);
  EXPECT_EQ(d.seqs, std::vector<std::uint8_t>{5});
  EXPECT_EQ(d.stats.bad_length, 2u);
}

TEST(FrameDecoder, FalseHeaderInNoiseDoesNotHideFrames) {
  // A plausible Counts header claiming 136 payload bytes, then three short real frames: the
  // candidate fails its CRC and the real frames inside it are found on the rescan.
  Bytes stream{kSync0, kSync1, 136, 0x81, 0x00};
  for (std::uint8_t s = 10; s < 13; ++s) {
    const Bytes f = heartbeat_frame(s);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  for (int i = 0; i < 140; ++i) stream.push_back(0x00);
  const Decoded d = decode(stream);
  EXPECT_EQ(d.seqs, (std::vector<std::uint8_t>{10, 11, 12}));
  EXPECT_EQ(d.stats.bad_crc, 1u);
}

TEST(FrameDecoder, ResetKeepsStatistics) {
  FrameDecoder dec;
  const Bytes f = counts_frame(1, 24, 0);
  dec.feed(std::span<const std::uint8_t>(f).first(10), [](const Frame&) {});
  EXPECT_EQ(dec.buffered(), 10u);
  dec.reset();
  EXPECT_EQ(dec.buffered(), 0u);
  EXPECT_EQ(dec.stats().discarded, 10u);
  int n = 0;
  dec.feed(f, [&](const Frame&) { ++n; });
  EXPECT_EQ(n, 1);
}

}  // namespace
}  // namespace spidar::device::protocol
