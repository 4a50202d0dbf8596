#pragma once
/// The serial link's budget per servo cycle. Each cycle the host sends one SetCommands frame and
/// the device answers it with one Counts frame; the answer starts only once the request is in, so
/// both frames follow each other on the line within one period (docs/protocol.md, "Timing and
/// baud rate"). In 8N1 a byte takes 10 bit times, so a rate needs
///     baud ≥ (SetCommands bytes + Counts bytes) × 10 × rate,
/// e.g. SPIDAR-8 (24 strings: 55 + 111 bytes) at 1 kHz needs 1 660 000 baud, before any firmware
/// or OS latency. (Full duplex alone would allow more: the Counts direction by itself carries
/// baud / 10 / Counts bytes; but then request and answer no longer fit in one period.)
#include <cstddef>

#include "spidar/core/result.hpp"

namespace spidar::device {

/// Bit times of one byte on an 8N1 line: start bit, 8 data bits, stop bit.
inline constexpr int kBitsPerByte = 10;

/// Bytes one servo cycle puts on the line for `strings` strings: SetCommands + Counts.
std::size_t link_bytes_per_cycle(int strings);
/// Smallest baud rate that carries `rate_hz` [Hz] cycles of `strings` strings.
double min_baud(int strings, double rate_hz);
/// Highest servo rate [Hz] a line at `baud` carries for `strings` strings.
double max_rate_hz(int baud, int strings);

/// Ok if `baud` carries `rate_hz` cycles of `strings` strings; else an error naming `what` (the
/// port), the baud rate, the strings, the rate, the bytes per cycle, the minimum baud rate
/// needed (and the smallest standard rate that is enough) and the highest rate this baud carries.
Status check_link_budget(const char* what, int baud, int strings, double rate_hz);

}  // namespace spidar::device
