#include "spidar/strings/encoder.hpp"

#include <cmath>

namespace spidar::strings {

std::int64_t length_to_counts(const EncoderChannel& ch, double length) {
  return std::llround((length - ch.length_at_zero) / (ch.sign * ch.metres_per_count));
}

std::int64_t wrap_counter(std::int64_t count, int bits) {
  const std::int64_t range = std::int64_t{1} << bits;
  const std::int64_t half = range >> 1;
  std::int64_t v = (count + half) % range;
  if (v < 0) v += range;
  return v - half;
}

std::int64_t CounterUnwrapper::update(std::int64_t raw) {
  if (!initialised_) {
    initialised_ = true;
    last_raw_ = raw;
    total_ = raw;
    return total_;
  }
  total_ += wrap_counter(raw - last_raw_, bits_);
  last_raw_ = raw;
  return total_;
}

}  // namespace spidar::strings
