#pragma once
/// Encoder counts ↔ string length. A string's length is affine in its (unwrapped) count:
///   l = length_at_zero + sign · metres_per_count · count.
/// Device counters are `bits` wide and signed (SPIDAR-8: 24 bits) and wrap around;
/// `CounterUnwrapper` turns the raw readings into a continuous count.
#include <cstdint>

namespace spidar::strings {

struct EncoderChannel {
  int sign = 1;                      ///< +1 if the count grows as the string pays out, else −1
  double metres_per_count = 2.924e-5;  ///< [m/count]
  double length_at_zero = 0.0;       ///< string length at count 0 [m]
};

/// String length [m] at an unwrapped count.
inline double counts_to_length(const EncoderChannel& ch, std::int64_t count) {
  return ch.length_at_zero + ch.sign * ch.metres_per_count * static_cast<double>(count);
}

/// Nearest count for a length [m] (what an ideal encoder would read).
std::int64_t length_to_counts(const EncoderChannel& ch, double length);

/// Wraps an unwrapped count into a signed `bits`-wide counter, as the device hardware does.
std::int64_t wrap_counter(std::int64_t count, int bits);

/// Follows a wrapping signed counter; assumes fewer than 2^(bits−1) counts between readings.
class CounterUnwrapper {
 public:
  explicit CounterUnwrapper(int bits = 24) : bits_(bits) {}
  /// Feeds a raw reading; returns the continuous count (the first reading is taken as is).
  std::int64_t update(std::int64_t raw);
  void reset() { initialised_ = false; }

 private:
  int bits_;
  bool initialised_ = false;
  std::int64_t last_raw_ = 0;
  std::int64_t total_ = 0;
};

}  // namespace spidar::strings
