#include "spidar/device/link_budget.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include "spidar/device/protocol.hpp"
#include "spidar/device/serial_port.hpp"

namespace spidar::device {

std::size_t link_bytes_per_cycle(int strings) {
  return protocol::frame_size(protocol::set_commands_payload(strings)) +
         protocol::frame_size(protocol::counts_payload(strings));
}

double min_baud(int strings, double rate_hz) {
  return static_cast<double>(link_bytes_per_cycle(strings)) * kBitsPerByte * rate_hz;
}

double max_rate_hz(int baud, int strings) {
  return static_cast<double>(baud) /
         (static_cast<double>(link_bytes_per_cycle(strings)) * kBitsPerByte);
}

Status check_link_budget(const char* what, int baud, int strings, double rate_hz) {
  const double needed = min_baud(strings, rate_hz);
  if (static_cast<double>(baud) >= needed) return Ok{};
  const int standard = standard_baud_at_least(needed);
  char advice[160];
  if (standard > 0) {
    std::snprintf(advice, sizeof advice, "the smallest standard rate that is enough is %d baud",
                  standard);
  } else {
    std::snprintf(advice, sizeof advice,
                  "no standard rate is enough (the fastest is 4000000 baud): lower the rate or "
                  "serve fewer strings per link");
  }
  char msg[512];
  std::snprintf(msg, sizeof msg,
                "%s: %d baud cannot carry %d strings at %g Hz: each servo cycle sends a "
                "SetCommands frame and gets a Counts frame back, %zu bytes = %zu bit times, so "
                "%g Hz needs at least %.0f baud (%d baud carries at most %.0f Hz); %s",
                what, baud, strings, rate_hz, link_bytes_per_cycle(strings),
                link_bytes_per_cycle(strings) * kBitsPerByte, rate_hz, std::ceil(needed), baud,
                std::floor(max_rate_hz(baud, strings)), advice);
  return Error{std::string(msg)};
}

}  // namespace spidar::device
