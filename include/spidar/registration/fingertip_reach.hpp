#pragma once
/// Each digit posed on its own so that its cap reaches the string-measured fingertip: the escape
/// from the straight-finger local minimum of the successive adjustment.
///
/// A finger's cap, seen from its MCP joint, moves along the bone when the distal (coupled) angle
/// changes near the straight pose only to second order: a Gauss-Newton fit that starts (or
/// arrives) with a finger nearly straight and too long for its measured cap compensates with MCP
/// flexion and stalls a millimetre or two short of the string, with the distal angle 0.5–0.8 rad
/// off (measured: registration_study --model-user, the left index from the first frame on). The
/// wrist and the other digits being held, each digit's own parameters (flexion, abduction where it
/// has one, distal) are few, so several starts across their ranges are cheap: a few damped
/// Gauss-Newton steps from each, the start whose cap ends nearest the measurement kept.
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"
#include "spidar/registration/successive_adjustment.hpp"

namespace spidar::registration {

struct FingertipReachParams {
  /// Only digits whose cap is farther than this from its measured fingertip are re-posed [m].
  double min_miss_m = 0.0;
  /// Distal angles spread evenly over its range, ends included (≥ 2), each started with the
  /// current flexion and with the flexion at ¼ and ¾ of its range; the current pose is always one
  /// more start.
  int starts = 5;
  /// Damped Gauss-Newton steps per start (≥ 1), and then from the best start (≥ 0).
  int iterations = 8;
  int polish_iterations = 24;
};

/// Which digits reach_fingertips re-posed (thumb, index, middle, ring) and their caps' miss
/// before and after [m].
struct FingertipReach {
  std::array<bool, hand::kFingertipCount> changed{};
  std::array<double, hand::kFingertipCount> miss_before_m{};
  std::array<double, hand::kFingertipCount> miss_after_m{};
  int changed_count() const;
};

/// Re-poses, in `q`, the parameters of each measured digit (hand::digit_params: flexion,
/// abduction, distal) whose cap misses its fingertip by more than `params.min_miss_m`, within the
/// model's joint limits, holding the wrist and the other digits; a digit changes only if its cap
/// ends nearer the measurement (by at least 0.01 mm). Invalid or non-finite fingertips are left
/// alone. The little finger follows the ring as in the model. Allocates nothing.
FingertipReach reach_fingertips(const hand::HandModel& model, const HandObservation& observation,
                                const FingertipReachParams& params, hand::HandParams* q);

/// After a fit (`*q`, `*report` from SuccessiveAdjustment::fit with `prior`): if a measured digit's
/// cap still misses its string by more than `reach.min_miss_m`, fits again from those digits
/// re-posed (reach_fingertips), with the prior's mean moved along for them (else the temporal
/// prior would hold the old basin), and keeps the re-fit if its cost without the prior term is
/// lower (the same reason). The report then carries both fits' iterations and the first's
/// cost_initial. Returns whether the re-fit was kept. `prior` may be null (no prior).
bool refit_reaching(const SuccessiveAdjustment& solver, const hand::HandModel& model,
                    const HandObservation& observation, const ImageEvidence& image,
                    const hand::HandParams* prior, const FingertipReachParams& reach,
                    hand::HandParams* q, FitReport* report);

/// The cap's distance from each measured fingertip at `q` [m]; 0 for one not measured.
std::array<double, hand::kFingertipCount> fingertip_misses(const hand::HandModel& model,
                                                           const HandObservation& observation,
                                                           const hand::HandParams& q);

}  // namespace spidar::registration
