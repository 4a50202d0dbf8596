#pragma once
/// Unit conversions for I/O boundaries. Inside spidar everything is SI.
#include <numbers>

namespace spidar::units {

inline constexpr double kPi = std::numbers::pi;

constexpr double deg_to_rad(double deg) { return deg * (kPi / 180.0); }
constexpr double rad_to_deg(double rad) { return rad * (180.0 / kPi); }
constexpr double mm_to_m(double mm) { return mm * 1e-3; }
constexpr double m_to_mm(double m) { return m * 1e3; }
constexpr double us_to_s(double us) { return us * 1e-6; }
constexpr double s_to_us(double s) { return s * 1e6; }

/// Standard gravity [m/s²].
inline constexpr double kGravity = 9.80665;

}  // namespace spidar::units
