#pragma once
/// The computation of one servo cycle, without threads or timing: encoder counts → string
/// lengths → fingertip positions; desired forces → tensions → motor commands. `ServoLoop` runs it
/// at a fixed rate; benchmarks and offline replays call it directly. Allocates nothing after
/// construction.
#include <cstdint>
#include <span>
#include <vector>

#include "spidar/device/device.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/device/unwrapped_counts.hpp"

namespace spidar::device {

class ServoCycle {
 public:
  /// `config` must outlive the cycle. Throws SpidarError if the device and config disagree.
  ServoCycle(const strings::DeviceConfig& config, const DeviceInfo& device);

  /// Counts → positions into `sample` (t_ns, p_W, consistent). A finger whose lengths are
  /// invalid keeps its previous position; invalid and inconsistent solves are counted in
  /// `inconsistent()`. What was measured stays readable below until the next call.
  void measure(const EncoderReading& reading, FingertipSample& sample);

  /// Forces → tensions → motor commands (clamped to the device's range). The sample gets what
  /// was computed: displayed forces `f_W`, tensions and commands. In the safe state, or for a
  /// non-finite force or position, a finger's motors get their minimum (tensions 0).
  void command(const ForceFrame& force, bool safe, FingertipSample& sample,
               std::span<std::int32_t> commands) const;
  /// Every motor at its minimum, and the sample says so (no force, tensions 0, the commands).
  void command_minimum(FingertipSample& sample, std::span<std::int32_t> commands) const;

  int string_count() const { return counts_.string_count(); }
  std::uint64_t inconsistent() const { return inconsistent_; }

  // --- the last `measure`, per device string k (0 … string_count−1) or finger f ---
  /// Unwrapped encoder counts of each string.
  std::span<const std::int64_t> counts() const { return counts_.counts(); }
  /// Length of each string [m].
  std::span<const double> lengths() const { return lengths_; }
  /// RMS length residual of each finger's solve [m]; NaN if its lengths were invalid or the
  /// solve failed.
  std::span<const double> residuals() const { return residual_; }
  /// First string of each finger (its strings are string_offset(f) … + n − 1).
  int string_offset(int finger) const { return string_offset_[finger]; }

 private:
  const strings::DeviceConfig& config_;
  DeviceInfo device_;
  strings::TensionLimits limits_;
  UnwrappedCounts counts_;
  std::vector<int> string_offset_;  // first string index of each finger
  std::uint64_t inconsistent_ = 0;
  std::vector<double> lengths_;       // per string [m]
  std::vector<double> residual_;      // per finger [m]
};

}  // namespace spidar::device
