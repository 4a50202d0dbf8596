#include "spidar/device/unwrapped_counts.hpp"

#include <string>

namespace spidar::device {

UnwrappedCounts::UnwrappedCounts(int string_count, int counter_bits) {
  if (string_count < 0 || string_count > kMaxDeviceStrings)
    throw SpidarError("unwrapped counts: " + std::to_string(string_count) +
                      " strings; expected 0 to " + std::to_string(kMaxDeviceStrings));
  unwrap_.assign(static_cast<std::size_t>(string_count), strings::CounterUnwrapper(counter_bits));
  counts_.assign(static_cast<std::size_t>(string_count), 0);
}

void UnwrappedCounts::update(const EncoderReading& reading) {
  for (std::size_t k = 0; k < unwrap_.size(); ++k)
    counts_[k] = unwrap_[k].update(reading.counts[k]);
}

void UnwrappedCounts::reset() {
  for (auto& u : unwrap_) u.reset();
}

}  // namespace spidar::device
