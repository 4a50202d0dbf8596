#include "spidar/strings/position.hpp"

#include "sym3.hpp"

#include <cmath>
#include <array>
#include <sstream>
#include <utility>

namespace spidar::strings {
namespace {


/// Distances and unit directions from each fulcrum to p, and the cost Σ (‖P − A_i‖ − l_i)².
struct Linearisation {
  std::array<double, kMaxStrings> r{};  ///< residuals ‖P − A_i‖ − l_i [m]
  std::array<Vec3, kMaxStrings> j = zeros<Vec3, kMaxStrings>();  ///< unit directions (P − A_i)/‖P − A_i‖
  double cost = 0.0;
};

void linearise(const PointGeometry& g, const Vec3& p, std::span<const double> l, Linearisation& L) {
  L.cost = 0.0;
  for (int i = 0; i < g.n; ++i) {
    const Vec3 d = p - g.p_WA[i];
    const double dist = d.norm();
    L.j[i] = dist > 1e-12 ? Vec3(d * (1.0 / dist)) : Vec3::Zero();  // at a fulcrum: no gradient
    L.r[i] = dist - l[i];
    L.cost += L.r[i] * L.r[i];
  }
}

/// Levenberg-Marquardt on Σ (‖P − A_i‖ − l_i)² from `p`, whose linearisation is `cur`. Stops
/// when the next step would be shorter than the tolerance. Returns iterations used; `cur` ends
/// as the linearisation at the returned `p`.
int refine(const PointGeometry& g, std::span<const double> l, const PositionSolverParams& prm,
           Vec3& p, Linearisation& cur) {
  Linearisation trial;
  double lambda = prm.initial_damping;
  int it = 0;
  while (it < prm.max_iterations) {
    ++it;
    Mat3 A = Mat3::Zero();
    Vec3 b = Vec3::Zero();
    for (int i = 0; i < g.n; ++i) {
      A.noalias() += cur.j[i] * cur.j[i].transpose();
      b.noalias() += cur.j[i] * cur.r[i];
    }
    bool accepted = false;
    for (int tries = 0; tries < 12 && !accepted; ++tries) {
      Mat3 Ad = A;
      Ad.diagonal().array() += lambda * (1.0 + A.diagonal().array());
      Vec3 step;
      if (!detail::solve_sym3(Ad, -b, step, 0.0) || !step.allFinite()) return it;
      if (step.squaredNorm() < prm.step_tolerance * prm.step_tolerance) return it;
      linearise(g, p + step, l, trial);
      if (trial.cost <= cur.cost) {
        p += step;
        std::swap(cur, trial);
        lambda = std::max(lambda * 0.1, 1e-15);
        accepted = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) break;
  }
  return it;
}

double cost(const PointGeometry& g, const Vec3& p, std::span<const double> l) {
  double c = 0.0;
  for (int i = 0; i < g.n; ++i) {
    const double r = (p - g.p_WA[i]).norm() - l[i];
    c += r * r;
  }
  return c;
}

}  // namespace

ClosedFormResult closed_form_position(const ClosedFormTriple& t, double l1, double l2, double l3,
                                      bool inner) {
  // (P − A1)·n1 = K1/d1 and (P − A1)·n2 = K2/d2 (paper eqs 8–12).
  const double a = (t.d1 * t.d1 + l1 * l1 - l2 * l2) / (2.0 * t.d1);
  const double b = (t.d2 * t.d2 + l1 * l1 - l3 * l3) / (2.0 * t.d2);
  const double alpha1 = (a - t.cos_theta * b) * t.inv_sin2_theta;
  const double alpha2 = (b - t.cos_theta * a) * t.inv_sin2_theta;
  const double q2 = alpha1 * alpha1 + alpha2 * alpha2 + 2.0 * t.cos_theta * alpha1 * alpha2;
  const double disc = l1 * l1 - q2;
  // Corrected eq. 7: α3·|n1×n2| = √(l1² − ‖α1n1 + α2n2‖²), along the unit normal.
  const double h = disc > 0.0 ? std::sqrt(disc) : 0.0;
  const Vec3 p = t.p_WA1 + alpha1 * t.n1 + alpha2 * t.n2 + (inner ? h : -h) * t.n3_inner;
  return {p, disc};
}

double length_residual_rms(const PointGeometry& g, const Vec3& p_WF,
                           std::span<const double> lengths) {
  return std::sqrt(cost(g, p_WF, lengths) / g.n);
}

Result<PositionEstimate> solve_position(const PointGeometry& g, std::span<const double> l,
                                        const PositionSolverParams& prm) {
  if (static_cast<int>(l.size()) != g.n) {
    return Error{"expected " + std::to_string(g.n) + " string lengths, got " +
                 std::to_string(l.size())};
  }
  for (int i = 0; i < g.n; ++i) {
    if (!std::isfinite(l[i]) || l[i] < 0.0) {
      std::ostringstream os;
      os << "string " << i << ": length " << l[i] << " m; expected a finite length >= 0";
      return Error{os.str()};
    }
  }
  const auto& tr = g.triple;
  const double l1 = l[tr.index[0]], l2 = l[tr.index[1]], l3 = l[tr.index[2]];
  const ClosedFormResult inner = closed_form_position(tr, l1, l2, l3, true);

  PositionEstimate est;
  if (g.n == 3 && inner.discriminant >= 0.0) {
    est.p_WF = inner.p_WF;
    est.residual = length_residual_rms(g, est.p_WF, l);
    est.consistent = est.residual <= prm.consistency_tolerance;
    return est;
  }

  Vec3 p = inner.p_WF;
  Linearisation lin;
  linearise(g, p, l, lin);
  if (g.n > 3 && inner.discriminant > 0.0) {
    // Extra strings see which mirror root is right.
    const Vec3 outer = closed_form_position(tr, l1, l2, l3, false).p_WF;
    Linearisation lin_outer;
    linearise(g, outer, l, lin_outer);
    if (lin_outer.cost < lin.cost) p = outer, lin = lin_outer;
  }
  est.iterations = refine(g, l, prm, p, lin);
  if (inner.discriminant < 0.0) {
    // The in-plane point can be a saddle of the least-squares cost; try once from inside.
    Vec3 q = inner.p_WF + 0.01 * tr.n3_inner;
    Linearisation lin_q;
    linearise(g, q, l, lin_q);
    est.iterations += refine(g, l, prm, q, lin_q);
    if (lin_q.cost < lin.cost) p = q, lin = lin_q;
  }
  est.p_WF = p;
  est.residual = std::sqrt(lin.cost / g.n);
  est.consistent = est.residual <= prm.consistency_tolerance;
  return est;
}

}  // namespace spidar::strings
