#include "spidar/hand/coupling.hpp"

#include <algorithm>
#include <cmath>

namespace spidar::hand {
namespace {
// The paper's printed coefficients: θ2 = a·θ1² + b·θ1.
constexpr double kQuadA = 1.1341;
constexpr double kQuadB = -0.286;
// θ_DIP = ⅔ θ_PIP  ⇒  θ_PIP = 1.5 θ_DIP.
constexpr double kLinearGain = 1.5;
}  // namespace

CoupledAngle couple(Coupling coupling, double distal) {
  switch (coupling) {
    case Coupling::kLinear:
      return {kLinearGain * distal, kLinearGain};
    case Coupling::kPaperQuadratic:
    default:
      return {(kQuadA * distal + kQuadB) * distal, 2.0 * kQuadA * distal + kQuadB};
  }
}

double distal_for_penultimate(Coupling coupling, double penultimate_max) {
  const double y = std::max(penultimate_max, 0.0);
  switch (coupling) {
    case Coupling::kLinear:
      return y / kLinearGain;
    case Coupling::kPaperQuadratic:
    default:
      // Larger root of a·x² + b·x − y = 0 (a > 0, y ≥ 0): the increasing branch.
      return (-kQuadB + std::sqrt(kQuadB * kQuadB + 4.0 * kQuadA * y)) / (2.0 * kQuadA);
  }
}

std::string_view coupling_name(Coupling coupling) {
  return coupling == Coupling::kLinear ? "linear" : "quadratic";
}

std::optional<Coupling> coupling_from_name(std::string_view name) {
  if (name == "quadratic") return Coupling::kPaperQuadratic;
  if (name == "linear") return Coupling::kLinear;
  return std::nullopt;
}

}  // namespace spidar::hand
