#pragma once
/// The binary wire protocol between the host and a microcontroller SPIDAR (docs/protocol.md).
///
/// Frame, all multi-byte fields little-endian:
///
///   offset  size  field
///   0       1     sync 0xA5
///   1       1     sync 0x5A
///   2       1     len   payload length in bytes (0 … kMaxPayload)
///   3       1     type  FrameType
///   4       1     seq   sequence number (wraps at 256)
///   5       len   payload
///   5+len   2     CRC-16/CCITT-FALSE over bytes 2 … 4+len (len, type, seq, payload), low byte first
///
/// Encoding writes into a caller-provided buffer and never allocates. `FrameDecoder` takes a
/// byte stream in arbitrary chunks, resynchronises after noise and counts errors by kind.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "spidar/device/device.hpp"

namespace spidar::device::protocol {

inline constexpr std::uint8_t kSync0 = 0xA5;
inline constexpr std::uint8_t kSync1 = 0x5A;
/// Bytes before the payload: sync0, sync1, len, type, seq.
inline constexpr std::size_t kHeaderSize = 5;
inline constexpr std::size_t kCrcSize = 2;
/// Largest payload: a Counts frame of kMaxDeviceStrings strings.
inline constexpr std::size_t kMaxPayload = 8 + 4 * kMaxDeviceStrings;
/// Largest frame on the wire [bytes].
inline constexpr std::size_t kMaxFrameSize = kHeaderSize + kMaxPayload + kCrcSize;

/// Frame types. Host→device types have the top bit clear, device→host types have it set.
enum class FrameType : std::uint8_t {
  kSetCommands = 0x01,   ///< host→device: n × int16 motor commands (DAC counts); answered by Counts
  kSetLimits = 0x02,     ///< host→device: int16 command_min, int16 command_max; not answered
  kHeartbeat = 0x03,     ///< host→device: empty; feeds the watchdog; answered by Counts
  kZeroCounters = 0x04,  ///< host→device: uint32 mask of strings to zero (bit i = string i)
  kCounts = 0x81,        ///< device→host: uint32 time [µs], uint32 status (Fault bits), n × int32
};

/// Total frame size on the wire for a payload of `payload_size` bytes.
constexpr std::size_t frame_size(std::size_t payload_size) {
  return kHeaderSize + payload_size + kCrcSize;
}
/// Payload size of a SetCommands frame for `n` strings [bytes].
constexpr std::size_t set_commands_payload(int n) { return 2 * static_cast<std::size_t>(n); }
/// Payload size of a Counts frame for `n` strings [bytes].
constexpr std::size_t counts_payload(int n) { return 8 + 4 * static_cast<std::size_t>(n); }

/// True if `type` is a known frame type and `payload_size` is a valid length for it.
bool valid_length(std::uint8_t type, std::size_t payload_size);
/// True if `type` is one of FrameType's values.
bool known_type(std::uint8_t type);
/// "set_commands", "counts", …; "unknown" for anything else.
const char* type_name(FrameType type);

/// CRC-16/CCITT-FALSE: polynomial 0x1021, initial value 0xFFFF, no reflection, no final XOR.
/// Check value: crc16("123456789") = 0x29B1.
std::uint16_t crc16(std::span<const std::uint8_t> bytes, std::uint16_t crc = 0xFFFF);

/// One decoded (or to-be-encoded) frame: type, sequence number and raw payload.
struct Frame {
  FrameType type = FrameType::kHeartbeat;
  std::uint8_t seq = 0;
  std::uint8_t payload_size = 0;
  std::array<std::uint8_t, kMaxPayload> payload{};

  std::span<const std::uint8_t> payload_bytes() const { return {payload.data(), payload_size}; }
};

// --- typed messages --------------------------------------------------------------------------

struct SetCommands {
  int count = 0;                                           ///< strings
  std::array<std::int16_t, kMaxDeviceStrings> commands{};  ///< [DAC counts]
};
struct SetLimits {
  std::int16_t command_min = 0;  ///< [DAC counts]
  std::int16_t command_max = 0;  ///< [DAC counts]
};
struct ZeroCounters {
  std::uint32_t mask = 0xFFFFFFFFu;  ///< bit i set = zero string i's counter
};
struct Counts {
  std::uint32_t device_time_us = 0;  ///< device clock [µs], wraps
  std::uint32_t status_flags = 0;    ///< Fault bits
  int count = 0;                     ///< strings
  std::array<std::int32_t, kMaxDeviceStrings> counts{};  ///< raw signed counter values
};

// --- encoding: each returns the bytes written, or 0 if `out` is too small or the input does
// not fit the protocol (more than kMaxDeviceStrings values, payload over kMaxPayload). ---------

/// Encodes a frame with a raw payload.
std::size_t encode_frame(std::span<std::uint8_t> out, FrameType type, std::uint8_t seq,
                         std::span<const std::uint8_t> payload);
std::size_t encode_frame(std::span<std::uint8_t> out, const Frame& frame);
std::size_t encode_set_commands(std::span<std::uint8_t> out, std::uint8_t seq,
                                std::span<const std::int16_t> commands);
std::size_t encode_set_limits(std::span<std::uint8_t> out, std::uint8_t seq, const SetLimits& m);
std::size_t encode_heartbeat(std::span<std::uint8_t> out, std::uint8_t seq);
std::size_t encode_zero_counters(std::span<std::uint8_t> out, std::uint8_t seq,
                                 const ZeroCounters& m);
std::size_t encode_counts(std::span<std::uint8_t> out, std::uint8_t seq, const Counts& m);

// --- parsing a decoded frame: false if the type differs or the payload length is invalid. ------

bool parse(const Frame& f, SetCommands& out);
bool parse(const Frame& f, SetLimits& out);
bool parse(const Frame& f, ZeroCounters& out);
bool parse(const Frame& f, Counts& out);

/// Decoder error and traffic counters. Every byte fed ends up in exactly one of: a decoded frame
/// (frame_bytes), discarded, or still buffered (`FrameDecoder::buffered()`).
struct DecoderStats {
  std::uint64_t bytes_in = 0;     ///< bytes fed
  std::uint64_t frames = 0;       ///< valid frames decoded
  std::uint64_t frame_bytes = 0;  ///< bytes of valid frames
  std::uint64_t discarded = 0;    ///< bytes dropped while hunting for a frame (noise, bad frames)
  std::uint64_t bad_crc = 0;      ///< candidate frames whose CRC did not match
  std::uint64_t bad_length = 0;   ///< length byte over kMaxPayload or invalid for the type
  std::uint64_t bad_type = 0;     ///< unknown type byte

  std::uint64_t errors() const { return bad_crc + bad_length + bad_type; }
};

/// Streaming decoder. Feed it chunks of any size; it calls `on_frame(const Frame&)` for every
/// valid frame, in order. After a bad CRC, length or type it drops only the first sync byte of the
/// failed candidate and rescans the bytes after it, so a real frame hidden behind noise that looks
/// like a header is still found. Holds at most kMaxFrameSize bytes; never allocates.
class FrameDecoder {
 public:
  template <typename OnFrame>
  void feed(std::span<const std::uint8_t> bytes, OnFrame&& on_frame) {
    while (!bytes.empty()) {
      bytes = bytes.subspan(append(bytes));
      while (extract()) on_frame(static_cast<const Frame&>(frame_));
    }
  }

  const DecoderStats& stats() const { return stats_; }
  /// Bytes held that may still become (part of) a frame.
  std::size_t buffered() const { return size_; }
  /// Drops buffered bytes (counted as discarded) and keeps the statistics.
  void reset();

 private:
  /// Appends the first byte of `bytes`, or, inside a candidate whose header checked out, as many
  /// as complete it. Returns the count appended (≥ 1).
  std::size_t append(std::span<const std::uint8_t> bytes);
  /// Scans the buffer; true when a valid frame was moved into `frame_`.
  bool extract();
  void drop(std::size_t n);

  std::array<std::uint8_t, kMaxFrameSize> buf_{};
  std::size_t size_ = 0;
  Frame frame_;
  DecoderStats stats_;
};

}  // namespace spidar::device::protocol
