#pragma once
/// Fingertip position from string lengths.
///
/// Three strings: the paper's closed form (eqs 1–12) with the corrected
///   α3 = √(l1² − ‖α1 n1 + α2 n2‖²) / sinθ
/// and the root on the frame's inner side. N ≥ 4 strings: damped Gauss-Newton least squares of
/// Σ (‖P − A_i‖ − l_i)², started from the closed form of the best triple (the mirror root with the
/// smaller residual). Inconsistent lengths (negative discriminant, broken triangle inequality)
/// give the least-squares estimate, flagged, with its residual — never NaN.
#include "spidar/core/result.hpp"
#include "spidar/strings/point_geometry.hpp"

namespace spidar::strings {

struct PositionSolverParams {
  int max_iterations = 30;           ///< Gauss-Newton iterations at most
  double step_tolerance = 1e-10;     ///< stop when the step is shorter [m] (encoders: ~25 µm)
  double initial_damping = 1e-9;     ///< Levenberg-Marquardt λ added to JᵀJ (dimensionless)
  double consistency_tolerance = 1e-3;  ///< RMS residual above which lengths are inconsistent [m]
};

struct PositionEstimate {
  Vec3 p_WF = Vec3::Zero();  ///< fingertip position [m], world
  bool consistent = true;    ///< lengths agree with one point within the tolerance
  double residual = 0.0;     ///< RMS of ‖P − A_i‖ − l_i [m]
  int iterations = 0;        ///< Gauss-Newton iterations used (0: closed form only)
};

/// Lengths must be finite and ≥ 0 (else an error naming the string), one per fulcrum.
Result<PositionEstimate> solve_position(const PointGeometry& geometry,
                                        std::span<const double> lengths,
                                        const PositionSolverParams& params = {});

/// The closed form on the geometry's triple alone. `discriminant` is l1² − ‖α1n1+α2n2‖² [m²];
/// when negative, the returned point is the in-plane one (α3 = 0). `inner` picks the root.
struct ClosedFormResult {
  Vec3 p_WF;
  double discriminant;
};
ClosedFormResult closed_form_position(const ClosedFormTriple& triple, double l1, double l2,
                                      double l3, bool inner = true);

/// RMS of ‖P − A_i‖ − l_i over the strings [m].
double length_residual_rms(const PointGeometry& geometry, const Vec3& p_WF,
                           std::span<const double> lengths);

}  // namespace spidar::strings
