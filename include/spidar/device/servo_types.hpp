#pragma once
/// Plain data exchanged by the servo loop and its users.
#include <array>
#include <cstdint>

#include "spidar/core/types.hpp"

namespace spidar::device {

inline constexpr int kMaxFingers = 8;

/// Fingertip state of one servo cycle (plain data; published through the ring).
struct FingertipSample {
  std::int64_t t_ns = 0;         ///< host monotonic time of the encoder reading [ns]
  std::uint64_t cycle = 0;
  std::uint32_t faults = 0;      ///< latched loop faults (Fault bits)
  std::uint32_t consistent = 0;  ///< bit f: finger f's lengths agreed with one point
  int finger_count = 0;
  std::array<std::array<double, 3>, kMaxFingers> p_W{};   ///< fingertip positions [m], world
  std::array<std::array<double, 3>, kMaxFingers> f_W{};   ///< displayed forces [N], world
};

/// Forces the fingers should feel, produced each cycle.
struct ForceFrame {
  std::int64_t t_ns = 0;  ///< when these forces were computed [ns]; stale data trips the watchdog
  std::array<std::array<double, 3>, kMaxFingers> f_W{};  ///< desired force per fingertip [N], world

  Vec3 force(int finger) const { return {f_W[finger][0], f_W[finger][1], f_W[finger][2]}; }
  void set_force(int finger, const Vec3& f) { f_W[finger] = {f.x(), f.y(), f.z()}; }
};

}  // namespace spidar::device
