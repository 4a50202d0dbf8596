#include "spidar/strings/stability_check.hpp"

#include <algorithm>
#include <cmath>

#include "spidar/strings/calibration.hpp"

namespace spidar::strings {

StabilityCheck::StabilityCheck(const FingerConfig& finger, const Vec3& p_W_target,
                               StabilityParams params)
    : finger_(finger), target_(p_W_target), p_(params) {}

void StabilityCheck::update(double t_s, std::span<const std::int64_t> counts) {
  const int n = finger_.geometry.n;
  window_.emplace_back(t_s, std::vector<std::int64_t>(counts.begin(), counts.begin() + n));
  while (!window_.empty() && window_.front().first < t_s - p_.hold_s) window_.pop_front();
  // Spread of each string over the window, in metres.
  spread_m_ = 0;
  for (int i = 0; i < n; ++i) {
    std::int64_t lo = window_.front().second[i], hi = lo;
    for (const auto& [t, c] : window_) {
      lo = std::min(lo, c[i]);
      hi = std::max(hi, c[i]);
    }
    spread_m_ =
        std::max(spread_m_, static_cast<double>(hi - lo) * finger_.channels[i].metres_per_count);
  }
  // Where the present calibration puts the fingertip.
  const auto p_W = fingertip_from_counts(finger_, counts);
  distance_m_ = p_W ? (*p_W - target_).norm() : 1e9;
  // Held still: the window covers hold_s and nothing moved more than the tolerance in it.
  if (spread_m_ > p_.tolerance_m || distance_m_ > p_.near_m || window_.size() == 1) {
    window_.clear();
    window_.emplace_back(t_s, std::vector<std::int64_t>(counts.begin(), counts.begin() + n));
    still_since_ = t_s;
    held_s_ = 0;
    return;
  }
  held_s_ = t_s - still_since_;
  ready_ = ready_ || held_s_ >= p_.hold_s;
}

std::vector<std::int64_t> StabilityCheck::sample() const {
  const int n = finger_.geometry.n;
  std::vector<std::int64_t> out(static_cast<std::size_t>(n), 0);
  if (window_.empty()) return out;
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (const auto& [t, c] : window_) sum += static_cast<double>(c[i]);
    out[i] = std::llround(sum / static_cast<double>(window_.size()));
  }
  return out;
}

}  // namespace spidar::strings
