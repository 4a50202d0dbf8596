#pragma once
/// Continuous encoder counts of every string of a device: the raw readings of its signed,
/// wrapping counters (`DeviceInfo::counter_bits` wide) unwrapped string by string. The servo
/// cycle and the calibration procedures read counts through this one class, so a calibration
/// relates lengths to the same counts the servo cycle turns into lengths.
#include <cstdint>
#include <span>
#include <vector>

#include "spidar/device/device.hpp"
#include "spidar/strings/encoder.hpp"

namespace spidar::device {

class UnwrappedCounts {
 public:
  /// `string_count` strings (≤ kMaxDeviceStrings) with `counter_bits`-wide counters.
  UnwrappedCounts(int string_count, int counter_bits);

  /// Feeds one reading (its first string_count counters); the first reading after construction
  /// or `reset` is taken as is. Assumes fewer than 2^(counter_bits−1) counts between readings.
  /// Allocates nothing.
  void update(const EncoderReading& reading);
  /// Forgets the history: the next reading is taken as is.
  void reset();

  /// The continuous count of each string after the last `update` [counts].
  std::span<const std::int64_t> counts() const { return counts_; }
  /// The strings first … first + n − 1 (e.g. one finger's: DeviceConfig::first_string).
  std::span<const std::int64_t> counts(int first, int n) const {
    return std::span<const std::int64_t>(counts_).subspan(static_cast<std::size_t>(first),
                                                          static_cast<std::size_t>(n));
  }
  int string_count() const { return static_cast<int>(counts_.size()); }

 private:
  std::vector<strings::CounterUnwrapper> unwrap_;
  std::vector<std::int64_t> counts_;
};

}  // namespace spidar::device
