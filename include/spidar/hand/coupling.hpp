#pragma once
/// Coupling of the last two joints of a digit (paper, Section 3): the distal angle θ1 is the
/// parameter and the penultimate angle θ2 follows from it.
///
/// - kPaperQuadratic (default), as printed: θ2 = 1.1341·θ1² − 0.286·θ1 [rad]. It dips to
///   θ2 ≈ −0.018 at θ1 = 0.126 and rises monotonically after, so the distal angle is the
///   natural parameter (the inverse θ2 → θ1 would be two-valued near zero).
/// - kLinear: θ_DIP = ⅔ θ_PIP, i.e. θ2 = 1.5·θ1.
///
/// Fingers: θ1 = DIP, θ2 = PIP. Thumb: θ1 = IP, θ2 = MCP.
#include <optional>
#include <string_view>

namespace spidar::hand {

enum class Coupling { kPaperQuadratic, kLinear };

/// The penultimate angle and its derivative with respect to the distal angle.
struct CoupledAngle {
  double penultimate = 0.0;    ///< θ2 [rad]
  double d_penultimate = 0.0;  ///< dθ2/dθ1 (dimensionless)
};

/// θ2(θ1) and dθ2/dθ1 for a distal angle θ1 [rad].
CoupledAngle couple(Coupling coupling, double distal);

/// The largest distal angle θ1 ≥ 0 whose penultimate angle θ2(θ1) does not exceed
/// `penultimate_max` [rad] (the increasing branch of the relation). penultimate_max ≥ 0.
double distal_for_penultimate(Coupling coupling, double penultimate_max);

/// "quadratic" / "linear".
std::string_view coupling_name(Coupling coupling);
std::optional<Coupling> coupling_from_name(std::string_view name);

}  // namespace spidar::hand
