#include "spidar/strings/motor.hpp"

#include <algorithm>
#include <cmath>

namespace spidar::strings {
namespace {
double full_scale(const MotorModel& m) { return static_cast<double>((1 << m.dac_bits) - 1); }
}  // namespace

double volts_per_newton(const MotorModel& m) {
  return m.pulley_radius / (m.torque_constant * m.amplifier_gain);
}

double max_drive_tension(const MotorModel& m) { return m.dac_v_max / volts_per_newton(m); }

double min_drive_tension(const MotorModel& m) {
  return std::max(0.0, m.dac_v_min / volts_per_newton(m));
}

MotorCommand tension_to_command(const MotorModel& m, double tension) {
  MotorCommand c;
  double v = std::isfinite(tension) ? tension * volts_per_newton(m) : m.dac_v_min;
  c.saturated = !(v >= m.dac_v_min && v <= m.dac_v_max);
  v = std::clamp(v, m.dac_v_min, m.dac_v_max);
  const double fs = full_scale(m);
  const double counts = std::round((v - m.dac_v_min) / (m.dac_v_max - m.dac_v_min) * fs);
  c.dac = static_cast<std::int32_t>(std::clamp(counts, 0.0, fs));
  c.volts = m.dac_v_min + c.dac / fs * (m.dac_v_max - m.dac_v_min);
  c.current = c.volts * m.amplifier_gain;
  return c;
}

double command_to_tension(const MotorModel& m, std::int32_t dac) {
  const double fs = full_scale(m);
  const double counts = std::clamp(static_cast<double>(dac), 0.0, fs);
  const double v = m.dac_v_min + counts / fs * (m.dac_v_max - m.dac_v_min);
  return v / volts_per_newton(m);
}

}  // namespace spidar::strings
