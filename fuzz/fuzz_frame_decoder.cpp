// libFuzzer target for the wire-protocol decoder (`make fuzz`). Also linked into
// test_device_serial, which runs every file of fuzz/corpus/frame_decoder through it.
//
// Invariants checked on every input (a violation aborts with a message):
//   - every decoded frame re-encodes to exactly the bytes it was decoded from;
//   - a typed frame parses, and its typed encoding equals the raw re-encoding;
//   - the re-encoded bytes decode again to one identical frame with no errors;
//   - byte accounting: bytes fed = frame bytes + discarded + still buffered;
//   - feeding the same input in other chunk sizes gives the same frames and statistics.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "spidar/device/protocol.hpp"

namespace {

namespace p = spidar::device::protocol;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "fuzz_frame_decoder: invariant violated: %s\n", what);
  std::abort();
}
void check(bool ok, const char* what) {
  if (!ok) fail(what);
}

bool same_frame(const p::Frame& a, const p::Frame& b) {
  return a.type == b.type && a.seq == b.seq && a.payload_size == b.payload_size &&
         std::memcmp(a.payload.data(), b.payload.data(), a.payload_size) == 0;
}

std::size_t typed_encode(const p::Frame& f, std::span<std::uint8_t> out) {
  switch (f.type) {
    case p::FrameType::kSetCommands: {
      p::SetCommands m;
      check(p::parse(f, m), "SetCommands parses");
      return p::encode_set_commands(out, f.seq, {m.commands.data(), static_cast<std::size_t>(m.count)});
    }
    case p::FrameType::kSetLimits: {
      p::SetLimits m;
      check(p::parse(f, m), "SetLimits parses");
      return p::encode_set_limits(out, f.seq, m);
    }
    case p::FrameType::kHeartbeat:
      return p::encode_heartbeat(out, f.seq);
    case p::FrameType::kZeroCounters: {
      p::ZeroCounters m;
      check(p::parse(f, m), "ZeroCounters parses");
      return p::encode_zero_counters(out, f.seq, m);
    }
    case p::FrameType::kCounts: {
      p::Counts m;
      check(p::parse(f, m), "Counts parses");
      return p::encode_counts(out, f.seq, m);
    }
  }
  fail("decoded frame of unknown type");
}

/// Frames and stats of one decode, for comparing chunkings.
struct Summary {
  std::uint64_t frames = 0;
  std::uint32_t hash = 2166136261u;  // FNV-1a over the frames' fields
  p::DecoderStats stats;
};

void mix(Summary& s, const p::Frame& f) {
  auto add = [&s](std::uint8_t b) { s.hash = (s.hash ^ b) * 16777619u; };
  add(static_cast<std::uint8_t>(f.type));
  add(f.seq);
  add(f.payload_size);
  for (std::size_t i = 0; i < f.payload_size; ++i) add(f.payload[i]);
  ++s.frames;
}

Summary decode_in_chunks(const std::uint8_t* data, std::size_t size, std::uint32_t seed) {
  Summary s;
  p::FrameDecoder dec;
  std::size_t pos = 0;
  std::uint32_t x = seed | 1u;
  while (pos < size) {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    const std::size_t n = std::min<std::size_t>(size - pos, 1 + x % 97);
    dec.feed({data + pos, n}, [&s](const p::Frame& f) { mix(s, f); });
    pos += n;
  }
  s.stats = dec.stats();
  return s;
}

bool same_stats(const p::DecoderStats& a, const p::DecoderStats& b) {
  return a.bytes_in == b.bytes_in && a.frames == b.frames && a.frame_bytes == b.frame_bytes &&
         a.discarded == b.discarded && a.bad_crc == b.bad_crc && a.bad_length == b.bad_length &&
         a.bad_type == b.bad_type;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  p::FrameDecoder dec;
  Summary whole;
  std::array<std::uint8_t, p::kMaxFrameSize> raw{};
  std::array<std::uint8_t, p::kMaxFrameSize> typed{};
  dec.feed({data, size}, [&](const p::Frame& f) {
    mix(whole, f);
    const std::size_t n = p::encode_frame(raw, f);
    check(n == p::frame_size(f.payload_size), "re-encoding has the frame's size");
    // Where the frame sat in the input: everything before it was fed and is no longer buffered.
    const std::uint64_t start = dec.stats().bytes_in - dec.buffered() - n;
    check(start + n <= size, "frame lies inside the input");
    check(std::memcmp(data + start, raw.data(), n) == 0, "frame re-encodes to its input bytes");
    check(typed_encode(f, typed) == n && std::memcmp(typed.data(), raw.data(), n) == 0,
          "typed encoding equals raw encoding");
    p::FrameDecoder again;
    int count = 0;
    again.feed({raw.data(), n}, [&](const p::Frame& g) {
      check(same_frame(f, g), "re-encoded frame decodes to itself");
      ++count;
    });
    check(count == 1 && again.stats().errors() == 0 && again.buffered() == 0,
          "re-encoded frame decodes cleanly once");
  });
  const p::DecoderStats& st = dec.stats();
  whole.stats = st;
  check(st.bytes_in == size, "every byte counted");
  check(st.bytes_in == st.frame_bytes + st.discarded + dec.buffered(), "byte accounting");
  check(dec.buffered() < p::kMaxFrameSize, "buffer bounded");
  check(st.discarded >= st.errors(), "each error discards at least one byte");

  for (std::uint32_t seed : {1u, 0x9E3779B9u}) {
    const Summary chunked = decode_in_chunks(data, size, seed ^ static_cast<std::uint32_t>(size));
    check(chunked.frames == whole.frames && chunked.hash == whole.hash &&
              same_stats(chunked.stats, whole.stats),
          "chunking does not change the result");
  }
  return 0;
}
