#include "layer_locks.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "spidar/core/types.hpp"
#include "spidar/core/units.hpp"

namespace spidar::physics {
namespace {

constexpr int kFaceAxis[6] = {2, 2, 1, 1, 0, 0};    // U D F B R L
constexpr int kFaceSign[6] = {+1, -1, -1, +1, +1, -1};
constexpr double kPieces = 26.0;                  // the cube's cubelets (a layer holds 9)

Vec3 vec(const mjtNum* p) { return {p[0], p[1], p[2]}; }
Quat quat(const mjtNum* q) { return Quat(q[0], q[1], q[2], q[3]).normalized(); }

/// The rotation nearest to R among the 24 that map the cube's axes onto each other.
Mat3 snap_rotation(const Mat3& R) {
  Mat3 S = Mat3::Zero();
  for (int c = 0; c < 3; ++c) {
    int r = 0;
    R.col(c).cwiseAbs().maxCoeff(&r);
    S(r, c) = R(r, c) > 0 ? 1.0 : -1.0;
  }
  return S;
}

}  // namespace

std::shared_ptr<LayerLocks> LayerLocks::Create(const mjModel* m, int core_body,
                                               const std::vector<Piece>& pieces,
                                               const DetentParams& params, double pitch) {
  for (const Piece& p : pieces)
    if (p.eq < 0) return nullptr;
  std::shared_ptr<LayerLocks> l(new LayerLocks());
  l->core_ = core_body;
  l->pieces_ = pieces;
  l->tau_.resize(pieces.size());
  l->riding_.resize(pieces.size());
  l->params_ = params;
  l->pitch_ = pitch;
  l->piece_of_body_.assign(static_cast<std::size_t>(m->nbody), -1);
  l->centre_.fill(-1);
  for (int i = 0; i < static_cast<int>(pieces.size()); ++i) {
    l->piece_of_body_[static_cast<std::size_t>(pieces[i].body)] = i;
    const int f = pieces[i].centre_of;
    if (f < 0) continue;
    l->centre_[f] = i;
    const int jnt = m->body_jntadr[pieces[i].body];
    l->hinge_qpos_[f] = m->jnt_qposadr[jnt];
    l->hinge_dof_[f] = m->jnt_dofadr[jnt];
  }
  for (int c : l->centre_)
    if (c < 0) return nullptr;
  return l;
}

bool LayerLocks::in_layer(const mjData* d, int piece, int face) const {
  const int b = pieces_[static_cast<std::size_t>(piece)].body;
  const Vec3 p_C = quat(d->xquat + 4 * core_).conjugate() * (vec(d->xpos + 3 * b) - vec(d->xpos + 3 * core_));
  return std::lround(p_C[kFaceAxis[face]] / pitch_) == kFaceSign[face];
}

void LayerLocks::weld(mjModel* m, const mjData* d, int piece, int body1, bool snap) {
  const Piece& pc = pieces_[static_cast<std::size_t>(piece)];
  const Quat q1 = quat(d->xquat + 4 * body1), q2 = quat(d->xquat + 4 * pc.body);
  Vec3 p_rel = q1.conjugate() * (vec(d->xpos + 3 * pc.body) - vec(d->xpos + 3 * body1));
  Quat q_rel = (q1.conjugate() * q2).normalized();
  if (snap) {
    for (int k = 0; k < 3; ++k) p_rel[k] = pitch_ * std::round(p_rel[k] / pitch_);
    q_rel = Quat(snap_rotation(q_rel.toRotationMatrix()));
  }
  // MuJoCo 2.2.2 weld data: anchor (3), body2's position in body1 (3), its orientation (4),
  // torque scale (1).
  mjtNum* e = m->eq_data + static_cast<std::ptrdiff_t>(pc.eq) * mjNEQDATA;
  m->eq_obj1id[pc.eq] = body1;
  e[3] = p_rel.x(), e[4] = p_rel.y(), e[5] = p_rel.z();
  e[6] = q_rel.w(), e[7] = q_rel.x(), e[8] = q_rel.y(), e[9] = q_rel.z();
  m->eq_active[pc.eq] = 1;
}

void LayerLocks::lock_all(mjModel* m, mjData* d) {
  for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) weld(m, d, i, core_, true);
  turning_ = -1;
  candidate_ = -1;
  candidate_s_ = settle_s_ = 0;
}

void LayerLocks::measure(const mjModel* m, const mjData* d) {
  // Torque of the external forces on each piece about the cube's centre [N·m], world axes.
  std::vector<Vec3>& tau = tau_;
  std::fill(tau.begin(), tau.end(), Vec3::Zero());
  const Vec3 c = vec(d->xpos + 3 * core_);
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& con = d->contact[i];
    const int p1 = piece_of_body_[static_cast<std::size_t>(m->geom_bodyid[con.geom1])];
    const int p2 = piece_of_body_[static_cast<std::size_t>(m->geom_bodyid[con.geom2])];
    if ((p1 >= 0) == (p2 >= 0)) continue;  // inside the cube, or not touching it
    mjtNum f6[6];
    mj_contactForce(m, d, i, f6);
    // The contact frame's rows are its axes (normal from geom1 toward geom2); f6 is the force
    // geom1 exerts on geom2 in that frame.
    Vec3 f_W = Vec3::Zero();
    for (int r = 0; r < 3; ++r) f_W += f6[r] * Vec3(con.frame[3 * r], con.frame[3 * r + 1], con.frame[3 * r + 2]);
    const Vec3 r_W = vec(con.pos) - c;
    if (p2 >= 0) tau[static_cast<std::size_t>(p2)] += r_W.cross(f_W);
    else tau[static_cast<std::size_t>(p1)] -= r_W.cross(f_W);
  }
  for (std::size_t i = 0; i < pieces_.size(); ++i) {
    const int b = pieces_[i].body;
    const Vec3 F = vec(d->xfrc_applied + 6 * b), T = vec(d->xfrc_applied + 6 * b + 3);
    tau[i] += (vec(d->xipos + 3 * b) - c).cross(F) + T;
  }
  Vec3 all = Vec3::Zero();
  for (const Vec3& t : tau) all += t;
  const Quat q_core = quat(d->xquat + 4 * core_);
  // While a layer turns, its pieces ride on its centre, not on the core: a force on one of them
  // twists the turning layer (or the cube), never a layer across it, which on a real cube cannot
  // move until the turning one is back at a click. So another layer's twist counts only its
  // pieces outside the turning layer, and their share of the cube's rigid motion.
  std::vector<char>& riding = riding_;
  const std::size_t n = pieces_.size();
  riding.assign(n, 0);
  if (turning_ >= 0)
    for (std::size_t i = 0; i < n; ++i) riding[i] = in_layer(d, static_cast<int>(i), turning_) ? 1 : 0;
  for (int f = 0; f < 6; ++f) {
    Vec3 layer = Vec3::Zero();
    int count = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (in_layer(d, static_cast<int>(i), f) && (f == turning_ || !riding[i])) {
        layer += tau[i];
        ++count;
      }
    Vec3 axis = Vec3::Zero();
    axis[kFaceAxis[f]] = kFaceSign[f];
    twist_[f] = (q_core * axis).dot(layer - (count / kPieces) * all);
  }
}

void LayerLocks::unlock(mjModel* m, const mjData* d, int face) {
  // The centre turns on its hinge; the layer's other pieces ride on the centre.
  const int centre = centre_[face];
  for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) {
    if (i == centre || !in_layer(d, i, face)) continue;
    weld(m, d, i, pieces_[static_cast<std::size_t>(centre)].body, false);
  }
  m->eq_active[pieces_[static_cast<std::size_t>(centre)].eq] = 0;
  turning_ = face;
  settle_s_ = 0;
  ++unlocks_;
}

void LayerLocks::lock_turning(mjModel* m, const mjData* d) {
  // Back onto the core, at the exact click nearest to where the layer is.
  for (int i = 0; i < static_cast<int>(pieces_.size()); ++i)
    if (in_layer(d, i, turning_)) weld(m, d, i, core_, true);
  turning_ = -1;
  settle_s_ = 0;
}

void LayerLocks::after_step(mjModel* m, mjData* d) {
  measure(m, d);
  const double dt = m->opt.timestep;
  const double brk = params_.breakaway_torque;
  double misalignment = 0;  // of the turning layer
  if (turning_ >= 0) {
    const int f = turning_;
    const double q = units::kPi / 2;
    const double a = d->qpos[hinge_qpos_[f]];
    misalignment = a - q * std::round(a / q);
    const bool resting = std::abs(misalignment) < params_.lock_tolerance_rad && std::abs(twist_[f]) < brk;
    settle_s_ = resting ? settle_s_ + dt : 0.0;
    if (settle_s_ + 1e-12 >= params_.settle_time_s) {
      lock_turning(m, d);
      return;
    }
  }
  // The layer twisted hardest, other than the one turning. It may take over from the turning
  // layer only while that one lies near a click (a layer held a little off its click by a grasp
  // would otherwise block every other turn; one half-way through a turn is being turned: a
  // free layer feels little twist however hard it is pushed, so its twist cannot tell).
  // It must clearly dominate the others: a jerky grasp twists several layers at once, a turning
  // hand one.
  int best = -1;
  double second = 0;
  for (int f = 0; f < 6; ++f) {
    if (f == turning_) continue;
    if (best < 0 || std::abs(twist_[f]) > std::abs(twist_[best])) {
      if (best >= 0) second = std::abs(twist_[best]);
      best = f;
    } else {
      second = std::max(second, std::abs(twist_[f]));
    }
  }
  const bool wants = std::abs(twist_[best]) > brk && std::abs(twist_[best]) >= params_.dominance * second &&
                     (turning_ < 0 || std::abs(misalignment) < params_.switch_tolerance_rad);
  if (!wants) {
    candidate_ = -1;
    candidate_s_ = 0;
    return;
  }
  candidate_s_ = best == candidate_ ? candidate_s_ + dt : dt;
  candidate_ = best;
  if (candidate_s_ + 1e-12 < params_.breakaway_time_s) return;
  if (turning_ >= 0) lock_turning(m, d);
  unlock(m, d, best);
  candidate_ = -1;
  candidate_s_ = 0;
}

}  // namespace spidar::physics
