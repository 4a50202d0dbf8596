#pragma once
// The residual blocks of the successive adjustment, visited one by one (residuals.hpp describes
// them). A sink receives each block (and its Jacobian when asked for): the solver accumulates the
// normal equations, the tests stack the rows. Everything is fixed-size; nothing allocates.
#include <algorithm>
#include <cmath>
#include <optional>

#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration::detail {

/// The residual terms, in ResidualTerm's order (residuals.hpp).
enum class Term { kFingertip, kWrist, kBand, kJointBall, kSilhouette, kPrior };
static_assert(static_cast<int>(Term::kPrior) == static_cast<int>(ResidualTerm::kPrior));

/// Points nearer the camera plane than this [m] are left out of the image terms.
inline constexpr double kMinImageDepth = 0.01;
/// A silhouette point counts as outside when farther than this from the silhouette [px].
inline constexpr double kSilhouetteTolerancePx = 0.5;

/// How far from `from` along `dir` (unit) the matte `alpha` leaves the silhouette (below
/// `threshold`) [px]: walked a pixel at a time (nearest pixel), the crossing then placed between the
/// last step on it and the first off it where the bilinear matte crosses the threshold. nullopt if
/// it does not within `max_px` (residuals.cpp).
std::optional<double> edge_along(const cv::Mat& alpha, const Vec2& from, const Vec2& dir, double max_px,
                                 double threshold);

template <int R>
using Block = Eigen::Matrix<double, R, 1>;
template <int R>
using BlockJacobian = Eigen::Matrix<double, R, hand::kParamCount>;
using PointJacobian = BlockJacobian<3>;

/// Forward kinematics at one θ, with the Jacobians when asked for.
struct PoseState {
  hand::HandPoints points;
  hand::FingertipJacobian J_tips;
  hand::JointJacobian J_joints;
  Mat3 A = Mat3::Identity();    ///< right-hand H coordinates → world (x mirrored for the left)
  Mat3 J_l = Mat3::Identity();  ///< SO(3) left Jacobian of the wrist's rotation vector
  Vec3 p_W_wrist = Vec3::Zero();
};

inline void pose_state(const hand::HandModel& model, const hand::HandParams& q, bool jacobians,
                       PoseState* s) {
  hand::forward_kinematics(model, q, &s->points, jacobians ? &s->J_tips : nullptr,
                           jacobians ? &s->J_joints : nullptr);
  s->A = hand::rotation_from_vector(q.r_W_hand());
  if (model.side == hand::Side::kLeft) s->A.col(0) = -s->A.col(0);
  if (jacobians) s->J_l = hand::so3_left_jacobian(q.r_W_hand());
  s->p_W_wrist = q.p_W_wrist();
}

/// A point fixed in the hand frame (right-hand coordinates p_H) and its Jacobian: the wrist
/// translation gives I, the rotation vector −[A p_H]× J_l (rotation_vector.hpp).
inline Vec3 rigid_point(const PoseState& s, const Vec3& p_H, PointJacobian* J) {
  const Vec3 d = s.A * p_H;
  if (J) {
    J->setZero();
    J->leftCols<3>().setIdentity();
    J->middleCols<3>(hand::kWristRotX) = -hand::skew(d) * s.J_l;
  }
  return s.p_W_wrist + d;
}

/// A joint and its Jacobian rows.
inline Vec3 joint_point(const PoseState& s, int joint, PointJacobian* J) {
  if (J) *J = s.J_joints.middleRows<3>(3 * joint);
  return s.points.p_W_joint[joint];
}

/// The proximal (end = 0) or distal (end = 1) end of a silhouette bone.
inline Vec3 bone_end(const hand::HandModel& model, const PoseState& s, BoneRef b, int end,
                     PointJacobian* J) {
  if (b.finger == hand::kThumb) return joint_point(s, hand::joint_index(b.finger, b.segment + end), J);
  if (b.segment == 0 && end == 0) return rigid_point(s, model.shape.digits[b.finger].p_H_base, J);
  return joint_point(s, hand::joint_index(b.finger, b.segment - 1 + end), J);
}

/// The point at t along a bone's axis and its Jacobian.
inline Vec3 bone_point(const hand::HandModel& model, const PoseState& s, BoneRef b, double t,
                       PointJacobian* J) {
  PointJacobian Ja, Jb;
  const Vec3 a = bone_end(model, s, b, 0, J ? &Ja : nullptr);
  const Vec3 c = bone_end(model, s, b, 1, J ? &Jb : nullptr);
  if (J) *J = (1.0 - t) * Ja + t * Jb;
  return (1.0 - t) * a + t * c;
}

/// The bracelet's centre: bracelet_offset_m along the forearm (`forearm_H`, unit, right-hand H
/// coordinates) from the wrist; frozen in the hand frame for one frame's fit.
inline Vec3 bracelet_point(const PoseState& s, const RegistrationParams& p, const Vec3& forearm_H,
                           PointJacobian* J) {
  return rigid_point(s, p.bracelet_offset_m * forearm_H, J);
}

/// A silhouette point's offset from its projected axis point [px], scaled with the bone's radius
/// in `model` over the radius it was frozen with (SilhouettePoint::radius_m).
inline Vec2 scaled_offset(const hand::HandModel& model, const SilhouettePoint& sp) {
  if (sp.bone < 0 || !(sp.radius_m > 0)) return sp.offset_px;
  const BoneRef b = silhouette_bone(sp.bone);
  return sp.offset_px * (model.shape.digits[b.finger].radius[b.segment] / sp.radius_m);
}

/// A ball enters the cost only where eq. 21 moves its joint (P̃ ≠ P). One wholly inside the
/// silhouette (or with a symmetric pattern of neighbours, or none on it) would add only
/// J_PᵀJ_P to A with nothing in b: a spring holding the joint where the current iterate put it,
/// which does not move the fixed point but slows convergence several-fold (measured: 3 → 15+
/// iterations from a 2 cm start).
inline bool ball_pulls(const JointBall& b) {
  return b.used && b.on_count > 0 && (b.target_px - b.centre_px).squaredNorm() > 1e-18;
}

inline bool wrist_observed(const HandObservation& o) {
  return o.wrist_px && o.wrist_px->allFinite() && std::isfinite(o.wrist_confidence) &&
         o.wrist_confidence > 0.0;
}

inline double prior_sigma(const RegistrationParams& p, int i) {
  if (i < hand::kWristRotX) return p.prior_sigma_wrist_m;
  if (i < hand::kThumbCmcFlexion) return p.prior_sigma_rotation_rad;
  return p.prior_sigma_joint_rad;
}

/// Visits every residual block at q with frozen targets. `s` is pose_state(q) (with Jacobians
/// when kJacobian). Sink: add<R>(Term, const Block<R>&, const BlockJacobian<R>* or null) and
/// add_prior(param, residual, d residual / d param).
template <bool kJacobian, class Sink>
void visit_residuals(const ResidualProblem& pr, const FrozenTargets& tg, const hand::HandParams& q,
                     const PoseState& s, Sink& sink) {
  const RegistrationParams& rp = *pr.params;
  const HandObservation& obs = *pr.observation;

  // Fingertips from the strings, 3D (with the projected wrist below: the paper's Q, linearised
  // Q(θ+Δθ) ≈ Q(θ) + J_Q Δθ, paper eqs 23–38).
  const double w_tip = 1.0 / rp.fingertip_sigma_m;
  for (int i = 0; i < hand::kFingertipCount; ++i) {
    if (!obs.fingertip_valid[i] || !obs.p_W_fingertip[i].allFinite()) continue;
    const Block<3> r = w_tip * (s.points.p_W_fingertip[i] - obs.p_W_fingertip[i]);
    if constexpr (kJacobian) {
      const BlockJacobian<3> J = w_tip * s.J_tips.middleRows<3>(3 * i);
      sink.template add<3>(Term::kFingertip, r, &J);
    } else {
      sink.template add<3>(Term::kFingertip, r, nullptr);
    }
  }

  const vision::Camera* camera = pr.image ? pr.image->camera : nullptr;
  if (camera) {
    vision::ProjectionJacobian Jp;
    PointJacobian J3;
    // One projected point: residual w (uv + offset − target), Jacobian w Jp J3.
    auto add_projected = [&](Term term, const Vec3& p, const Vec2& offset, const Vec2& target,
                             double w) {
      if constexpr (kJacobian) {
        const Vec2 uv = camera->project(p, &Jp);
        const Block<2> r = w * (uv + offset - target);
        const BlockJacobian<2> J = w * (Jp * J3);
        sink.template add<2>(term, r, &J);
      } else {
        const Block<2> r = w * (camera->project(p) + offset - target);
        sink.template add<2>(term, r, nullptr);
      }
    };
    PointJacobian* J3p = kJacobian ? &J3 : nullptr;

    // The projected wrist from the bracelet.
    if (tg.wrist_active && wrist_observed(obs)) {
      const double w = std::sqrt(std::min(obs.wrist_confidence, 1.0)) / rp.wrist_sigma_px;
      const Vec3 p = bracelet_point(s, rp, obs.forearm_H, J3p) + tg.bracelet_shift_W;
      add_projected(Term::kWrist, p, Vec2::Zero(), *obs.wrist_px, w);
    }
    // The band's extent in the image from two points frozen on it (right-hand H), relative to
    // the detected extent: no cost within `tol` (a dead zone: the model only assumes the user's
    // forearm), linear in the excess beyond it. `across` (unit) measures the extent across the
    // band's image axis; zero measures the distance itself.
    auto add_band_extent = [&](const std::array<Vec3, 2>& end_H, double detected, double sigma, double tol,
                               const Vec2& across) {
      const double w = std::sqrt(std::min(obs.wrist_confidence, 1.0)) / sigma;
      PointJacobian J0, J1;
      const Vec3 e0 = rigid_point(s, end_H[0], kJacobian ? &J0 : nullptr);
      const Vec3 e1 = rigid_point(s, end_H[1], kJacobian ? &J1 : nullptr);
      vision::ProjectionJacobian Jp0, Jp1;
      const Vec2 d = kJacobian ? Vec2(camera->project(e1, &Jp1) - camera->project(e0, &Jp0))
                               : Vec2(camera->project(e1) - camera->project(e0));
      const bool along_d = across.isZero();
      const double extent = along_d ? d.norm() : d.dot(across);
      const double excess = extent / detected - 1.0;  // relative
      const double beyond = excess > tol ? excess - tol : (excess < -tol ? excess + tol : 0.0);
      const Block<1> r = Block<1>::Constant(w * beyond);
      if constexpr (kJacobian) {
        BlockJacobian<1> J = BlockJacobian<1>::Zero();
        const Vec2 grad = along_d ? (extent > 1e-9 ? Vec2(d / extent) : Vec2(Vec2::Zero())) : across;
        if (beyond != 0.0) J = (w / detected) * grad.transpose() * (Jp1 * J1 - Jp0 * J0);
        sink.template add<1>(Term::kBand, r, &J);
      } else {
        sink.template add<1>(Term::kBand, r, nullptr);
      }
    };
    // The band's length across the forearm: how far along its ray the wrist is.
    if (tg.band_active)  // frozen only with the wrist term active (freeze_targets)
      add_band_extent(tg.band_end_H, obs.wrist_length_px, rp.bracelet_length_sigma, rp.bracelet_length_tolerance,
                      Vec2::Zero());
    // Its thickness across its image axis: how obliquely the camera sees the forearm.
    if (tg.thickness_active)
      add_band_extent(tg.thickness_end_H, obs.wrist_thickness_px, rp.bracelet_thickness_sigma,
                      rp.bracelet_thickness_tolerance, tg.thickness_dir_px);

    // Joint-balls (eq. 21): the projected joint toward its frozen target P̃; the P of the paper,
    // linearised P(θ+Δθ) ≈ P(θ) + J_P Δθ (paper eqs 23–38).
    const double w_ball = 1.0 / rp.joint_ball_sigma_px;
    for (int j = 0; j < hand::kJointCount; ++j) {
      const JointBall& b = tg.balls[j];
      if (!ball_pulls(b)) continue;
      const Vec3 p = joint_point(s, j, J3p);
      add_projected(Term::kJointBall, p, Vec2::Zero(), b.target_px, w_ball);
    }

    // The digits' axes: the projected axis point across its bone onto the edges' midpoint.
    if (tg.axis_count > 0) {
      const double w_axis = 1.0 / rp.digit_axis_sigma_px;
      for (int k = 0; k < tg.axis_count; ++k) {
        const DigitAxisPoint& ap = tg.axes[k];
        const Vec3 p = bone_point(*pr.model, s, silhouette_bone(ap.bone), ap.t, J3p);
        if constexpr (kJacobian) {
          const Vec2 uv = camera->project(p, &Jp);
          const Block<1> r = Block<1>::Constant(w_axis * ap.across_px.dot(uv - ap.target_px));
          const BlockJacobian<1> J = w_axis * (ap.across_px.transpose() * Jp * J3);
          sink.template add<1>(Term::kJointBall, r, &J);
        } else {
          const Block<1> r = Block<1>::Constant(w_axis * ap.across_px.dot(camera->project(p) - ap.target_px));
          sink.template add<1>(Term::kJointBall, r, nullptr);
        }
      }
    }

    // Silhouette points outside the real silhouette, toward their frozen nearest pixel.
    const double w_sil = 1.0 / rp.silhouette_sigma_px;
    for (int k = 0; k < tg.silhouette_count; ++k) {
      const SilhouettePoint& sp = tg.silhouette[k];
      const Vec3 p = bone_point(*pr.model, s, silhouette_bone(sp.bone), sp.t, J3p);
      add_projected(Term::kSilhouette, p, scaled_offset(*pr.model, sp), sp.target_px, w_sil);
    }
    // Owned silhouette pixels left uncovered, pulling the nearest part's edge.
    const double w_cov = 1.0 / rp.coverage_sigma_px;
    for (int k = 0; k < tg.coverage_count; ++k) {
      const SilhouettePoint& sp = tg.coverage[k];
      const hand::PalmBox& box = pr.model->shape.palm;
      const Vec3 p = sp.bone >= 0 ? bone_point(*pr.model, s, silhouette_bone(sp.bone), sp.t, J3p)
                                  : rigid_point(s, box.p_H_centre + sp.palm_u.cwiseProduct(box.half_extents), J3p);
      add_projected(Term::kSilhouette, p, scaled_offset(*pr.model, sp), sp.target_px, w_cov * sp.weight);
    }
  }

  // The temporal prior, per parameter: the paper's 17, and the little finger's own where it
  // moves on its own (toward the prior's little finger, or its ring finger's angles where the
  // prior's little finger copied them).
  if (pr.prior) {
    hand::HandParams prior = *pr.prior;
    if (!prior.little_independent) prior.set_little(prior.ring());
    const int n = q.little_independent ? hand::kParamCount : hand::kPaperParamCount;
    for (int i = 0; i < n; ++i) {
      const double mean = prior[i];
      if (!std::isfinite(mean)) continue;
      const double w = 1.0 / prior_sigma(rp, i);
      sink.add_prior(i, w * (q[i] - mean), w);
    }
  }
  // A little finger of its own stays near the ring finger's angles (no string measures it).
  if (q.little_independent) {
    const double w = 1.0 / rp.little_coupling_sigma_rad;
    for (int k = 0; k < 3; ++k) {
      const int little = hand::kLittleMcpFlexion + k, ring = hand::kRingMcpFlexion + k;
      const Block<1> r = Block<1>::Constant(w * (q[little] - q[ring]));
      if constexpr (kJacobian) {
        BlockJacobian<1> J = BlockJacobian<1>::Zero();
        J(0, little) = w;
        J(0, ring) = -w;
        sink.template add<1>(Term::kPrior, r, &J);
      } else {
        sink.template add<1>(Term::kPrior, r, nullptr);
      }
    }
  }
}

/// Adds a block's squared norm to its term.
inline void add_cost(TermCosts* c, Term t, double squared) {
  switch (t) {
    case Term::kFingertip: c->fingertip += squared; break;
    case Term::kWrist:
    case Term::kBand: c->wrist += squared; break;
    case Term::kJointBall: c->joint_ball += squared; break;
    case Term::kSilhouette: c->silhouette += squared; break;
    case Term::kPrior: c->prior += squared; break;
  }
}

/// Per-term costs only.
struct CostSink {
  TermCosts costs;
  template <int R>
  void add(Term t, const Block<R>& r, const BlockJacobian<R>*) {
    add_cost(&costs, t, r.squaredNorm());
  }
  void add_prior(int, double r, double) { costs.prior += r * r; }
};

/// The normal equations A = Σ JᵀJ, b = −Σ Jᵀr and the costs: the paper's A = J_QᵀJ_Q + c J_PᵀJ_P
/// and b = J_Qᵀ(Q̃ − Q) + c J_Pᵀ(P̃ − P) (paper eqs 23–38), with every term weighted by its σ.
struct NormalEquationsSink {
  Eigen::Matrix<double, hand::kParamCount, hand::kParamCount> A =
      Eigen::Matrix<double, hand::kParamCount, hand::kParamCount>::Zero();
  hand::ParamVec b = hand::ParamVec::Zero();
  TermCosts costs;
  template <int R>
  void add(Term t, const Block<R>& r, const BlockJacobian<R>* J) {
    add_cost(&costs, t, r.squaredNorm());
    A.noalias() += J->transpose() * *J;
    b.noalias() -= J->transpose() * r;
  }
  void add_prior(int i, double r, double j) {
    costs.prior += r * r;
    A(i, i) += j * j;
    b[i] -= j * r;
  }
};

}  // namespace spidar::registration::detail
