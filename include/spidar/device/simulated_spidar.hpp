#pragma once
/// A simulated SPIDAR: strings from the configured fulcrums to simulated fingertip caps.
///
/// - Encoders: the true string length (plus sag when slack) through per-string true channels
///   (config scale × (1 + scale error)), rounded to counts, with Gaussian count noise, wrapped
///   to the counter width. Counters read 0 with the fingertips at the pole (as after zeroing).
/// - Motors: DAC command → tension through the configured drive (saturating at the DAC range),
///   then a first-order lag. A string whose tension falls below `slack_tension` goes slack: it
///   pulls nothing and reads up to `slack_sag` long.
/// - Fingertips: mass-spring-damper of a human fingertip between the FingertipSource's goal and
///   the cap, pushed by the string forces, integrated in sub-steps (fingertip_impedance.hpp): its
///   stiffness isotropic, or shaped like the finger's own where the source gives holds().
/// - Time: by default the simulation follows the host's monotonic clock (real time); with
///   `fixed_step_s` > 0 each read advances exactly that much (deterministic tests).
/// - Faults to inject: disconnect after a time, a read that hangs past the timeout, an
///   over-current flag.
#include <memory>
#include <random>
#include <vector>

#include "spidar/core/seqlock.hpp"
#include "spidar/device/device.hpp"
#include "spidar/device/fingertip_impedance.hpp"
#include "spidar/device/fingertip_source.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/strings/device_config.hpp"

namespace spidar::device {

struct SimulatedSpidarParams {
  double count_noise = 0.5;            ///< encoder noise [counts RMS]
  double scale_error = 0.0;            ///< σ of each string's true/configured m-per-count − 1
  double motor_time_constant = 0.5e-3; ///< [s] first-order lag of tension behind the command
  double slack_tension = 0.2;          ///< [N] below this a string is slack
  double slack_sag = 0.002;            ///< [m] extra length read by a fully slack string
  double max_substep = 0.25e-3;        ///< [s] integration step limit
  double fixed_step_s = 0.0;           ///< > 0: advance this much per read instead of real time
  FingertipImpedance impedance;
  std::uint64_t seed = 1;
  // Fault injection (times in seconds since open; < 0: never).
  double disconnect_after_s = -1;      ///< reads and writes fail as disconnected
  double hang_after_s = -1;            ///< one read blocks for `hang_duration_s`
  double hang_duration_s = 0.1;
};

/// Ground truth the simulator exposes for tests and metrics.
struct SimulatedTruth {
  double t_s = 0;
  std::vector<Vec3> p_W_fingertip;   ///< true cap positions [m]
  std::vector<Vec3> f_W_strings;     ///< force the strings apply to each cap [N]
  std::vector<double> tension;       ///< actual tension per string [N]
  std::vector<bool> slack;
};

class SimulatedSpidar final : public Device {
 public:
  SimulatedSpidar(const strings::DeviceConfig& config, SimulatedSpidarParams params,
                  std::shared_ptr<FingertipSource> source);

  Status open() override;
  void close() override;
  const DeviceInfo& info() const override { return info_; }
  Status read(EncoderReading& out) override;
  Status write(std::span<const std::int32_t> commands) override;
  void request_safe_state() override { safe_.store(true, std::memory_order_release); }
  void clear_safe_state() override { safe_.store(false, std::memory_order_release); }
  DeviceStatus status() const override;

  /// Advances the simulation by dt [s] (used by read(); public for tests).
  void advance(double dt_s);
  /// A copy of the ground truth (not for the servo path: allocates; not thread-safe while the
  /// servo thread reads: use truth_samples() then).
  SimulatedTruth truth() const;
  /// Ground truth as seen at each read(), for other threads (lock-free): up to `max` newest
  /// samples, newest first, into `out`; returns how many. t_ns is the host time of the read,
  /// p_W the true cap positions [m], f_W the force the strings apply to each cap [N].
  std::size_t truth_samples(FingertipSample* out, std::size_t max) const {
    return truth_ring_.newest(out, max);
  }
  /// The commands in effect (after clamping and the safe state).
  std::span<const std::int32_t> applied_commands() const { return applied_; }
  /// Sets the over-current flag reported in status_flags (fault injection).
  void inject_over_current(bool on) { over_current_.store(on); }

 private:
  struct String {
    int finger;
    Vec3 p_WA;
    strings::EncoderChannel truth;
    double tension = 0;
  };
  void step(double dt_s);
  /// The source's holds for the goals just read (sanitised), or isotropic ones.
  void take_holds();

  strings::DeviceConfig config_;
  SimulatedSpidarParams params_;
  std::shared_ptr<FingertipSource> source_;
  DeviceInfo info_;
  std::vector<String> strings_;
  std::vector<Vec3> x_, v_, goal_, force_;
  std::vector<FingertipHold> hold_;
  std::vector<std::int32_t> commands_, applied_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
  double t_s_ = 0;
  std::int64_t opened_ns_ = 0, last_ns_ = 0;
  bool open_ = false, hung_ = false;
  std::atomic<bool> safe_{true}, over_current_{false};
  std::atomic<std::uint32_t> faults_{kFaultNone};
  FingertipSample truth_sample_;
  std::uint64_t reads_ = 0;
  core::SampleRing<FingertipSample, 1024> truth_ring_;
};

}  // namespace spidar::device
