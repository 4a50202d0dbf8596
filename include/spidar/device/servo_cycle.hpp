#pragma once
/// The computation of one servo cycle, without threads or timing: encoder counts → string
/// lengths → fingertip positions; desired forces → tensions → motor commands. `ServoLoop` runs it
/// at a fixed rate; benchmarks and offline replays call it directly. Allocates nothing after
/// construction.
#include <span>
#include <vector>

#include "spidar/device/device.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/encoder.hpp"

namespace spidar::device {

class ServoCycle {
 public:
  /// `config` must outlive the cycle. Throws SpidarError if the device and config disagree.
  ServoCycle(const strings::DeviceConfig& config, const DeviceInfo& device);

  /// Counts → positions into `sample` (t_ns, p_W, consistent). A finger whose lengths are
  /// invalid or inconsistent keeps its previous position and is counted in `inconsistent()`.
  void measure(const EncoderReading& reading, FingertipSample& sample);

  /// Forces → motor commands (clamped to the device's range) and the displayed forces into
  /// `sample.f_W`. In the safe state, or for a non-finite force, the motors get their minimum.
  void command(const ForceFrame& force, bool safe, FingertipSample& sample,
               std::span<std::int32_t> commands) const;

  int string_count() const { return static_cast<int>(unwrap_.size()); }
  std::uint64_t inconsistent() const { return inconsistent_; }

 private:
  const strings::DeviceConfig& config_;
  DeviceInfo device_;
  strings::TensionLimits limits_;
  std::vector<strings::CounterUnwrapper> unwrap_;
  std::vector<int> string_offset_;  // first string index of each finger
  std::uint64_t inconsistent_ = 0;
};

}  // namespace spidar::device
