#pragma once
/// String tension ↔ motor command through the drive chain:
///   tension t [N] → torque t·r [N·m] → current τ/k_t [A] → amplifier input i/g [V]
///   → DAC counts round((V − V_min)/(V_max − V_min) · (2^bits − 1)), saturated.
/// SPIDAR-8: r = 8 mm, k_t = 0.0277 N·m/A, g = 0.5 A/V → 0.5776 V/N; 12-bit DAC 0–10 V, so the
/// drive saturates at 17.3 N, below the 30 N string limit.
#include <cstdint>

namespace spidar::strings {

struct MotorModel {
  double pulley_radius = 0.008;         ///< [m]
  double torque_constant = 0.0277;      ///< [N·m/A]
  double amplifier_gain = 0.5;          ///< [A/V]
  int dac_bits = 12;
  double dac_v_min = 0.0;               ///< [V] at DAC count 0
  double dac_v_max = 10.0;              ///< [V] at full scale
};

struct MotorCommand {
  double current = 0.0;      ///< motor current [A] after saturation
  double volts = 0.0;        ///< amplifier input [V] after saturation
  std::int32_t dac = 0;      ///< DAC counts
  bool saturated = false;    ///< the requested tension was outside the drive's range
};

/// Volts per newton of string tension [V/N].
double volts_per_newton(const MotorModel& m);
/// Largest tension the drive can produce [N] (full-scale DAC).
double max_drive_tension(const MotorModel& m);
/// Smallest tension the drive can produce [N] (DAC count 0).
double min_drive_tension(const MotorModel& m);
/// Command for a tension [N]; saturates at the DAC range (strings only pull).
MotorCommand tension_to_command(const MotorModel& m, double tension);
/// Tension [N] the drive produces at a DAC count (clamped to the DAC range).
double command_to_tension(const MotorModel& m, std::int32_t dac);

}  // namespace spidar::strings
