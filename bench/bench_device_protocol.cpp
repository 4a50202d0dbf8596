// Serial wire protocol: encode and decode of the two frames of a SPIDAR-8 servo cycle
// (24 strings): SetCommands host→device (55 bytes), Counts device→host (111 bytes).
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>

#include "spidar/device/protocol.hpp"

namespace {

namespace p = spidar::device::protocol;
constexpr int kStrings = 24;

p::Counts sample_counts() {
  p::Counts c;
  c.device_time_us = 123456789;
  c.status_flags = 0;
  c.count = kStrings;
  for (int i = 0; i < kStrings; ++i) c.counts[i] = (i % 2 ? -1 : 1) * (i * 4099 + 1);
  return c;
}

void EncodeCounts24(benchmark::State& state) {
  p::Counts c = sample_counts();
  std::array<std::uint8_t, p::kMaxFrameSize> buf{};
  std::uint8_t seq = 0;
  for (auto _ : state) {
    c.device_time_us += 1000;
    benchmark::DoNotOptimize(p::encode_counts(buf, seq++, c));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * p::frame_size(p::counts_payload(kStrings)));
}
BENCHMARK(EncodeCounts24);

void DecodeCounts24(benchmark::State& state) {
  std::array<std::uint8_t, p::kMaxFrameSize> buf{};
  const std::size_t n = p::encode_counts(buf, 1, sample_counts());
  p::FrameDecoder dec;
  p::Counts out;
  for (auto _ : state) {
    dec.feed({buf.data(), n}, [&out](const p::Frame& f) { p::parse(f, out); });
    benchmark::DoNotOptimize(out);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(DecodeCounts24);

void EncodeSetCommands24(benchmark::State& state) {
  std::array<std::int16_t, kStrings> cmd{};
  for (int i = 0; i < kStrings; ++i) cmd[i] = static_cast<std::int16_t>(100 * i);
  std::array<std::uint8_t, p::kMaxFrameSize> buf{};
  std::uint8_t seq = 0;
  for (auto _ : state) {
    cmd[0] = static_cast<std::int16_t>(seq);
    benchmark::DoNotOptimize(p::encode_set_commands(buf, seq++, cmd));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * p::frame_size(p::set_commands_payload(kStrings)));
}
BENCHMARK(EncodeSetCommands24);

void DecodeSetCommands24(benchmark::State& state) {
  std::array<std::int16_t, kStrings> cmd{};
  for (int i = 0; i < kStrings; ++i) cmd[i] = static_cast<std::int16_t>(100 * i);
  std::array<std::uint8_t, p::kMaxFrameSize> buf{};
  const std::size_t n = p::encode_set_commands(buf, 1, cmd);
  p::FrameDecoder dec;
  p::SetCommands out;
  for (auto _ : state) {
    dec.feed({buf.data(), n}, [&out](const p::Frame& f) { p::parse(f, out); });
    benchmark::DoNotOptimize(out);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(DecodeSetCommands24);

}  // namespace
