#pragma once
/// Joint ranges of the hand and the parameter box they imply.
///
/// Defaults are the common anatomical ranges: MCP flexion −15…90°, MCP abduction
/// ±20°, PIP 0…110°, DIP 0…90°, thumb CMC flexion ±60°, CMC abduction 0…70°; thumb MCP 0…60° and
/// IP 0…80° are our own choice (not among those common ranges). The coupled distal parameter is limited so
/// that both coupled joints stay in range: θ1 ∈ [dip.lo, min(dip.hi, θ1 where θ2 = pip.hi)].
/// With the paper's quadratic the PIP angle dips to −0.018 rad for small θ1, slightly below a
/// PIP range starting at 0: that is the printed relation and is accepted.
/// The wrist parameters (position, rotation vector) are unbounded.
#include <limits>

#include "spidar/core/result.hpp"
#include "spidar/core/units.hpp"
#include "spidar/hand/coupling.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

/// A closed range [lo, hi] [rad].
struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};

/// Anatomical joint ranges [rad], the same for both hands.
struct JointRanges {
  Interval mcp_flexion{units::deg_to_rad(-15.0), units::deg_to_rad(90.0)};
  Interval mcp_abduction{units::deg_to_rad(-20.0), units::deg_to_rad(20.0)};
  Interval pip_flexion{0.0, units::deg_to_rad(110.0)};
  Interval dip_flexion{0.0, units::deg_to_rad(90.0)};
  Interval thumb_cmc_flexion{units::deg_to_rad(-60.0), units::deg_to_rad(60.0)};
  Interval thumb_cmc_abduction{0.0, units::deg_to_rad(70.0)};
  Interval thumb_mcp_flexion{0.0, units::deg_to_rad(60.0)};
  Interval thumb_ip_flexion{0.0, units::deg_to_rad(80.0)};
};

/// Checks every range: finite, lo < hi, within ±π, and distal/penultimate ranges starting at
/// ≥ 0 (the coupling is only defined for non-negative distal flexion). The error names the range.
Status validate_joint_ranges(const JointRanges& ranges);

/// Lower and upper bound of every parameter (±∞ for the wrist).
struct ParamLimits {
  ParamVec lower = ParamVec::Constant(-std::numeric_limits<double>::infinity());
  ParamVec upper = ParamVec::Constant(std::numeric_limits<double>::infinity());
};

/// The parameter box implied by the joint ranges under a coupling (see the file comment). The
/// little finger's own parameters (17..19) take the fingers' ranges.
ParamLimits parameter_limits(const JointRanges& ranges, Coupling coupling);

/// How far past its active range an external force can push a finger's MCP joint [rad]: the
/// passive range of motion, where the collateral ligaments and the volar plate stop the joint.
/// Clinical goniometry gives passive MCP hyperextension 15–30° past the active and passive
/// abduction about 10° past the active; we take the low ends. The thumb and the distal joints
/// have none here (their passive range over the active is small).
struct PassiveRange {
  double mcp_extension = units::deg_to_rad(15.0);  ///< past the lower end of MCP flexion
  double mcp_abduction = units::deg_to_rad(10.0);  ///< past both ends of MCP abduction
};

/// The parameter box widened from the active `limits` by the passive range (index, middle and ring
/// MCP flexion and abduction): where a finger can be pushed, not where it moves by itself.
ParamLimits passive_limits(const ParamLimits& limits, const PassiveRange& passive = {});

/// Parameters clamped into the box. NaN parameters become the nearest finite bound's midpoint
/// (or 0 for unbounded ones), so nothing downstream sees NaN.
HandParams clamp_to_limits(const HandParams& params, const ParamLimits& limits);

/// True when every parameter is within [lower − tol, upper + tol].
bool within_limits(const HandParams& params, const ParamLimits& limits, double tol = 0.0);

}  // namespace spidar::hand
