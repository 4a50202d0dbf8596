#pragma once
/// Calibration of the encoder channels of one point's strings.
///
/// Pole calibration (the paper's): the fingertip rests at a known point (the pole's tip, the
/// world origin); each string's length there is ‖A_i − p‖, which fixes its offset.
///
/// Multi-point calibration: the fingertip is placed at several known points of a jig; per
/// string, ‖A_i − p_j‖ = l0_i + s_i k_i c_ij is a straight line in the count, so offset l0_i and
/// metres-per-count k_i (with its sign) come from linear least squares, with residuals.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/encoder.hpp"
#include "spidar/strings/point_geometry.hpp"

namespace spidar::strings {

/// Where calibration `channels` put a finger's fingertip for its (unwrapped) `counts` [m], world;
/// nullopt if the string lengths do not give a position.
std::optional<Vec3> fingertip_from_counts(const FingerConfig& finger,
                                          std::span<const EncoderChannel> channels,
                                          std::span<const std::int64_t> counts);
/// The same with the finger's own channels.
inline std::optional<Vec3> fingertip_from_counts(const FingerConfig& finger,
                                                 std::span<const std::int64_t> counts) {
  return fingertip_from_counts(finger, finger.channels, counts);
}

/// Channels with `length_at_zero` set so that the lengths at `counts` equal ‖A_i − p_W_pole‖.
/// Sign and metres-per-count are kept.
Result<std::vector<EncoderChannel>> pole_calibrate(const PointGeometry& geometry,
                                                   std::span<const EncoderChannel> channels,
                                                   std::span<const std::int64_t> counts,
                                                   const Vec3& p_W_pole);

/// One jig placement: where the fingertip was put [m], world, and the counts read there.
struct JigSample {
  Vec3 p_WF;
  std::vector<std::int64_t> counts;
};

struct StringFit {
  EncoderChannel channel;   ///< fitted sign, metres per count and offset
  double residual_rms = 0;  ///< RMS of the fit's length residuals [m]
  double residual_max = 0;  ///< largest |residual| [m]
};

/// Fits every string's channel from ≥ 2 samples (≥ 3 recommended, spread over the workspace).
/// Fails with the string index if its counts do not vary enough to fit a slope.
Result<std::vector<StringFit>> fit_multipoint(const PointGeometry& geometry,
                                              std::span<const JigSample> samples);

}  // namespace spidar::strings

namespace spidar::strings {

/// How well calibrated channels locate the fingertip: at each test point, the counts an ideal
/// encoder with the `true_channels` would read are turned into lengths with `calibrated` and
/// solved for position. Returns the RMS position error [m] over the points.
Result<double> position_error_rms(const PointGeometry& geometry,
                                  std::span<const EncoderChannel> true_channels,
                                  std::span<const EncoderChannel> calibrated,
                                  std::span<const Vec3> p_W_test);

/// Points of a regular n×n×n jig grid centred at `p_W_centre` with `spacing` [m].
std::vector<Vec3> jig_grid(const Vec3& p_W_centre, double spacing, int n);

}  // namespace spidar::strings
