#include "spidar/device/protocol.hpp"

#include <algorithm>
#include <cstring>

namespace spidar::device::protocol {
namespace {

constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    auto c = static_cast<std::uint16_t>(i << 8);
    for (int k = 0; k < 8; ++k) {
      c = static_cast<std::uint16_t>((c & 0x8000u) ? (c << 1) ^ 0x1021u : (c << 1));
    }
    t[i] = c;
  }
  return t;
}
constexpr std::array<std::uint16_t, 256> kCrcTable = make_crc_table();

void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint16_t get_u16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t get_u32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) |
         (std::uint32_t{p[3]} << 24);
}

/// Writes header and CRC around a payload already in place at out[kHeaderSize…].
std::size_t finish_frame(std::span<std::uint8_t> out, FrameType type, std::uint8_t seq,
                         std::size_t payload_size) {
  out[0] = kSync0;
  out[1] = kSync1;
  out[2] = static_cast<std::uint8_t>(payload_size);
  out[3] = static_cast<std::uint8_t>(type);
  out[4] = seq;
  const std::uint16_t crc = crc16(out.subspan(2, 3 + payload_size));
  put_u16(out.data() + kHeaderSize + payload_size, crc);
  return frame_size(payload_size);
}

bool fits(std::span<std::uint8_t> out, std::size_t payload_size) {
  return payload_size <= kMaxPayload && out.size() >= frame_size(payload_size);
}

}  // namespace

std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t crc) {
  for (const std::uint8_t b : bytes) {
    crc = static_cast<std::uint16_t>((crc << 8) ^ kCrcTable[((crc >> 8) ^ b) & 0xFFu]);
  }
  return crc;
}

bool known_type(std::uint8_t type) {
  switch (static_cast<FrameType>(type)) {
    case FrameType::kSetCommands:
    case FrameType::kSetLimits:
    case FrameType::kHeartbeat:
    case FrameType::kZeroCounters:
    case FrameType::kCounts:
      return true;
  }
  return false;
}

bool valid_length(std::uint8_t type, std::size_t n) {
  switch (static_cast<FrameType>(type)) {
    case FrameType::kSetCommands:
      return n % 2 == 0 && n <= set_commands_payload(kMaxDeviceStrings);
    case FrameType::kSetLimits:
      return n == 4;
    case FrameType::kHeartbeat:
      return n == 0;
    case FrameType::kZeroCounters:
      return n == 4;
    case FrameType::kCounts:
      return n >= 8 && (n - 8) % 4 == 0 && n <= counts_payload(kMaxDeviceStrings);
  }
  return false;
}

const char* type_name(FrameType type) {
  switch (type) {
    case FrameType::kSetCommands: return "set_commands";
    case FrameType::kSetLimits: return "set_limits";
    case FrameType::kHeartbeat: return "heartbeat";
    case FrameType::kZeroCounters: return "zero_counters";
    case FrameType::kCounts: return "counts";
  }
  return "unknown";
}

std::size_t encode_frame(std::span<std::uint8_t> out, FrameType type, std::uint8_t seq,
                         std::span<const std::uint8_t> payload) {
  if (!fits(out, payload.size())) return 0;
  if (!payload.empty()) std::memcpy(out.data() + kHeaderSize, payload.data(), payload.size());
  return finish_frame(out, type, seq, payload.size());
}

std::size_t encode_frame(std::span<std::uint8_t> out, const Frame& frame) {
  return encode_frame(out, frame.type, frame.seq, frame.payload_bytes());
}

std::size_t encode_set_commands(std::span<std::uint8_t> out, std::uint8_t seq,
                                std::span<const std::int16_t> commands) {
  if (commands.size() > static_cast<std::size_t>(kMaxDeviceStrings)) return 0;
  const std::size_t n = 2 * commands.size();
  if (!fits(out, n)) return 0;
  std::uint8_t* p = out.data() + kHeaderSize;
  for (std::size_t i = 0; i < commands.size(); ++i) {
    put_u16(p + 2 * i, static_cast<std::uint16_t>(commands[i]));
  }
  return finish_frame(out, FrameType::kSetCommands, seq, n);
}

std::size_t encode_set_limits(std::span<std::uint8_t> out, std::uint8_t seq, const SetLimits& m) {
  if (!fits(out, 4)) return 0;
  put_u16(out.data() + kHeaderSize, static_cast<std::uint16_t>(m.command_min));
  put_u16(out.data() + kHeaderSize + 2, static_cast<std::uint16_t>(m.command_max));
  return finish_frame(out, FrameType::kSetLimits, seq, 4);
}

std::size_t encode_heartbeat(std::span<std::uint8_t> out, std::uint8_t seq) {
  if (!fits(out, 0)) return 0;
  return finish_frame(out, FrameType::kHeartbeat, seq, 0);
}

std::size_t encode_zero_counters(std::span<std::uint8_t> out, std::uint8_t seq,
                                 const ZeroCounters& m) {
  if (!fits(out, 4)) return 0;
  put_u32(out.data() + kHeaderSize, m.mask);
  return finish_frame(out, FrameType::kZeroCounters, seq, 4);
}

std::size_t encode_counts(std::span<std::uint8_t> out, std::uint8_t seq, const Counts& m) {
  if (m.count < 0 || m.count > kMaxDeviceStrings) return 0;
  const std::size_t n = counts_payload(m.count);
  if (!fits(out, n)) return 0;
  std::uint8_t* p = out.data() + kHeaderSize;
  put_u32(p, m.device_time_us);
  put_u32(p + 4, m.status_flags);
  for (int i = 0; i < m.count; ++i) put_u32(p + 8 + 4 * i, static_cast<std::uint32_t>(m.counts[i]));
  return finish_frame(out, FrameType::kCounts, seq, n);
}

bool parse(const Frame& f, SetCommands& out) {
  if (f.type != FrameType::kSetCommands || !valid_length(0x01, f.payload_size)) return false;
  out.count = f.payload_size / 2;
  for (int i = 0; i < out.count; ++i) {
    out.commands[i] = static_cast<std::int16_t>(get_u16(f.payload.data() + 2 * i));
  }
  return true;
}

bool parse(const Frame& f, SetLimits& out) {
  if (f.type != FrameType::kSetLimits || f.payload_size != 4) return false;
  out.command_min = static_cast<std::int16_t>(get_u16(f.payload.data()));
  out.command_max = static_cast<std::int16_t>(get_u16(f.payload.data() + 2));
  return true;
}

bool parse(const Frame& f, ZeroCounters& out) {
  if (f.type != FrameType::kZeroCounters || f.payload_size != 4) return false;
  out.mask = get_u32(f.payload.data());
  return true;
}

bool parse(const Frame& f, Counts& out) {
  if (f.type != FrameType::kCounts || !valid_length(0x81, f.payload_size)) return false;
  const std::uint8_t* p = f.payload.data();
  out.device_time_us = get_u32(p);
  out.status_flags = get_u32(p + 4);
  out.count = (f.payload_size - 8) / 4;
  for (int i = 0; i < out.count; ++i) {
    out.counts[i] = static_cast<std::int32_t>(get_u32(p + 8 + 4 * i));
  }
  return true;
}

// --- FrameDecoder --------------------------------------------------------------------------------

std::size_t FrameDecoder::append(std::span<const std::uint8_t> bytes) {
  // extract() leaves at most one incomplete candidate (< kMaxFrameSize bytes), so there is room.
  // With 4 or more bytes held, extract() has checked sync, length and type: the candidate just
  // waits for its remaining bytes, and nothing can happen before they are all there.
  std::size_t n = 1;
  if (size_ >= 4) n = std::min(bytes.size(), frame_size(buf_[2]) - size_);
  std::memcpy(buf_.data() + size_, bytes.data(), n);
  size_ += n;
  stats_.bytes_in += n;
  return n;
}

void FrameDecoder::drop(std::size_t n) {
  std::memmove(buf_.data(), buf_.data() + n, size_ - n);
  size_ -= n;
}

void FrameDecoder::reset() {
  stats_.discarded += size_;
  size_ = 0;
}

bool FrameDecoder::extract() {
  for (;;) {
    // Hunt for the first sync byte.
    std::size_t skip = 0;
    while (skip < size_ && buf_[skip] != kSync0) ++skip;
    if (skip > 0) {
      stats_.discarded += skip;
      drop(skip);
    }
    if (size_ < 2) return false;
    if (buf_[1] != kSync1) {
      ++stats_.discarded;
      drop(1);
      continue;
    }
    if (size_ < 3) return false;
    const std::size_t len = buf_[2];
    if (len > kMaxPayload) {
      ++stats_.bad_length;
      ++stats_.discarded;
      drop(1);
      continue;
    }
    if (size_ < 4) return false;
    const std::uint8_t type = buf_[3];
    if (!known_type(type)) {
      ++stats_.bad_type;
      ++stats_.discarded;
      drop(1);
      continue;
    }
    if (!valid_length(type, len)) {
      ++stats_.bad_length;
      ++stats_.discarded;
      drop(1);
      continue;
    }
    const std::size_t total = frame_size(len);
    if (size_ < total) return false;
    const std::uint16_t crc = crc16(std::span<const std::uint8_t>(buf_.data() + 2, 3 + len));
    if (crc != get_u16(buf_.data() + kHeaderSize + len)) {
      ++stats_.bad_crc;
      ++stats_.discarded;
      drop(1);
      continue;
    }
    frame_.type = static_cast<FrameType>(type);
    frame_.seq = buf_[4];
    frame_.payload_size = static_cast<std::uint8_t>(len);
    std::memcpy(frame_.payload.data(), buf_.data() + kHeaderSize, len);
    ++stats_.frames;
    stats_.frame_bytes += total;
    drop(total);
    return true;
  }
}

}  // namespace spidar::device::protocol
