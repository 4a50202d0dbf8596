#include "spidar/device/fault_log.hpp"

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <vector>

#include "spidar/device/device.hpp"

namespace spidar::device {

void FaultLog::record(std::uint32_t bits, const char* text) noexcept {
  Entry e;
  std::snprintf(e.text.data(), e.text.size(), "%s", text ? text : "");
  for (int b = 0; b < 32; ++b) {
    const std::uint32_t bit = 1u << b;
    if (!(bits & bit)) continue;
    if (writing_.fetch_or(bit, std::memory_order_acq_rel) & bit) continue;  // another writer
    e.order = order_.fetch_add(1, std::memory_order_acq_rel) + 1;
    slots_[static_cast<std::size_t>(b)].publish(e);
    writing_.fetch_and(~bit, std::memory_order_acq_rel);
  }
}

void FaultLog::vrecordf(std::uint32_t bits, const char* format, std::va_list args) noexcept {
  std::array<char, kTextSize> text{};
  std::vsnprintf(text.data(), text.size(), format, args);
  record(bits, text.data());
}

void FaultLog::recordf(std::uint32_t bits, const char* format, ...) noexcept {
  std::va_list args;
  va_start(args, format);
  vrecordf(bits, format, args);
  va_end(args);
}

std::string FaultLog::describe(std::uint32_t faults) const {
  struct Line {
    std::uint64_t order;
    std::uint32_t bit;
    std::string text;
  };
  std::vector<Line> lines;
  for (int b = 0; b < 32; ++b) {
    const std::uint32_t bit = 1u << b;
    if (!(faults & bit)) continue;
    const auto e = slots_[static_cast<std::size_t>(b)].read();
    if (e && e->text[0] != '\0') {
      lines.push_back({e->order, bit, std::string(e->text.data())});
    } else {
      lines.push_back({UINT64_MAX, bit, "no details recorded"});
    }
  }
  std::stable_sort(lines.begin(), lines.end(),
                   [](const Line& a, const Line& b) { return a.order < b.order; });
  std::string out;
  for (const auto& l : lines) {
    if (!out.empty()) out += "; ";
    const char* name = fault_name(l.bit);
    if (name) {
      out += name;
    } else {
      out += "bit ";
      out += std::to_string(std::countr_zero(l.bit));
    }
    out += ": ";
    out += l.text;
  }
  return out;
}

}  // namespace spidar::device
