#include <string>
#include <utility>

#include "spidar/device/device.hpp"

namespace spidar::device {
namespace {

constexpr std::pair<std::uint32_t, const char*> kNames[] = {
    {kFaultDisconnected, "disconnected"},    {kFaultReadTimeout, "read_timeout"},
    {kFaultProtocol, "protocol"},            {kFaultOverCurrent, "over_current"},
    {kFaultEmergencyStop, "emergency_stop"}, {kFaultWatchdog, "watchdog"},
    {kFaultDeadlineMiss, "deadline_miss"},   {kFaultForceStall, "force_stall"},
    {kFaultStaleCounts, "stale_counts"},     {kFaultWorkspace, "workspace"},
    {kFaultInconsistent, "inconsistent"},    {kFaultEncoderGlitch, "encoder_glitch"},
    {kFaultFrozenClock, "frozen_clock"},
};

}  // namespace

const char* fault_name(std::uint32_t bit) {
  for (const auto& [b, name] : kNames) {
    if (b == bit) return name;
  }
  return nullptr;
}

std::string fault_names(std::uint32_t faults) {
  std::string out;
  for (const auto& [bit, name] : kNames) {
    if (!(faults & bit)) continue;
    if (!out.empty()) out += ',';  // `+=`, not `"," + std::string`: GCC 12 -Wrestrict false positive
    out += name;
  }
  return out.empty() ? "none" : out;
}

}  // namespace spidar::device
