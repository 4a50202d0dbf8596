#pragma once
/// Plain data exchanged by the servo loop and its users.
#include <algorithm>
#include <array>
#include <cstdint>

#include "spidar/core/types.hpp"
#include "spidar/device/device.hpp"

namespace spidar::device {

inline constexpr int kMaxFingers = 8;

/// Fingertip state of one servo cycle (plain data; published through the ring): what the cycle
/// measured and what it commanded, so readers (GUI, recorder, report) never solve again.
struct FingertipSample {
  std::int64_t t_ns = 0;         ///< host monotonic time of the encoder reading [ns]
  std::uint64_t cycle = 0;
  std::uint32_t faults = 0;      ///< latched loop faults (Fault bits)
  std::uint32_t consistent = 0;  ///< bit f: finger f's lengths agreed with one point
  int finger_count = 0;
  std::array<std::array<double, 3>, kMaxFingers> p_W{};   ///< fingertip positions [m], world
  std::array<std::array<double, 3>, kMaxFingers> f_W{};   ///< displayed forces [N], world
  /// Device strings in `tension` and `command` (the config's order: finger by finger).
  int string_count = 0;
  /// Tension the cycle solved for each string [N] (paper eqs 13–14); 0 where the motor got its
  /// minimum command without a solve (safe state, no valid position or force).
  std::array<double, kMaxDeviceStrings> tension{};
  /// Motor command sent to each string [DAC counts], after clamping to the device's range.
  std::array<std::int32_t, kMaxDeviceStrings> command{};
};

/// Fingertip f's position [m], world, as a vector.
inline Vec3 fingertip_position(const FingertipSample& s, int f) {
  return {s.p_W[f][0], s.p_W[f][1], s.p_W[f][2]};
}
/// Fingertip f's displayed force [N], world, as a vector.
inline Vec3 fingertip_force(const FingertipSample& s, int f) {
  return {s.f_W[f][0], s.f_W[f][1], s.f_W[f][2]};
}
/// The positions of the sample's fingertips [m], world: entries 0 … finger_count−1, zero beyond.
/// The one conversion of a sample to vectors; allocates nothing.
inline std::array<Vec3, kMaxFingers> fingertip_positions(const FingertipSample& s) {
  std::array<Vec3, kMaxFingers> p_W;
  p_W.fill(Vec3::Zero());
  for (int f = 0; f < std::min(s.finger_count, kMaxFingers); ++f) p_W[f] = fingertip_position(s, f);
  return p_W;
}

/// Forces the fingers should feel, produced each cycle.
struct ForceFrame {
  std::int64_t t_ns = 0;  ///< when these forces were computed [ns]; stale data trips the watchdog
  std::array<std::array<double, 3>, kMaxFingers> f_W{};  ///< desired force per fingertip [N], world

  Vec3 force(int finger) const { return {f_W[finger][0], f_W[finger][1], f_W[finger][2]}; }
  void set_force(int finger, const Vec3& f) { f_W[finger] = {f.x(), f.y(), f.z()}; }
};

}  // namespace spidar::device
