#include <string>

#include "spidar/device/device.hpp"

namespace spidar::device {

std::string fault_names(std::uint32_t faults) {
  static constexpr std::pair<std::uint32_t, const char*> kNames[] = {
      {kFaultDisconnected, "disconnected"},   {kFaultReadTimeout, "read_timeout"},
      {kFaultProtocol, "protocol"},           {kFaultOverCurrent, "over_current"},
      {kFaultEmergencyStop, "emergency_stop"}, {kFaultWatchdog, "watchdog"},
      {kFaultDeadlineMiss, "deadline_miss"},  {kFaultForceStall, "force_stall"},
      {kFaultStaleCounts, "stale_counts"},
  };
  std::string out;
  for (const auto& [bit, name] : kNames) {
    if (!(faults & bit)) continue;
    if (!out.empty()) out += ',';  // `+=`, not `"," + std::string`: GCC 12 -Wrestrict false positive
    out += name;
  }
  return out.empty() ? "none" : out;
}

}  // namespace spidar::device
