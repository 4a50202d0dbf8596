#include "spidar/physics/rubiks_cube.hpp"

#include <mujoco/mujoco.h>

#include <cmath>
#include <random>

#include "layer_locks.hpp"
#include "spidar/core/units.hpp"

namespace spidar::physics {
namespace {

constexpr char kFaces[] = "UDFBRL";

/// Axis (0 x, 1 y, 2 z) and sign of a face.
std::pair<int, int> face_axis(char face) {
  switch (face) {
    case 'U': return {2, +1};
    case 'D': return {2, -1};
    case 'F': return {1, -1};
    case 'B': return {1, +1};
    case 'R': return {0, +1};
    case 'L': return {0, -1};
    default: return {-1, 0};
  }
}

int face_index(char face) {
  for (int i = 0; i < 6; ++i)
    if (kFaces[i] == face) return i;
  return -1;
}

}  // namespace

Result<RubiksCube> RubiksCube::Attach(World& world, const DetentParams& detent) {
  const mjModel* m = world.model();
  RubiksCube cube;
  cube.world_ = &world;
  cube.core_ = world.body_id("cube");
  if (cube.core_ < 0) return Error{world.scene_path() + ": no body named 'cube' (not a Rubik's cube scene)"};
  for (int x = 0; x < 3; ++x) {
    for (int y = 0; y < 3; ++y) {
      for (int z = 0; z < 3; ++z) {
        if (x == 1 && y == 1 && z == 1) continue;
        const std::string name = "cubelet_" + std::to_string(x) + std::to_string(y) + std::to_string(z);
        Cubelet c;
        c.body = world.body_id(name);
        if (c.body < 0) return Error{world.scene_path() + ": cube body '" + name + "' missing"};
        const int jnt = m->body_jntadr[c.body];
        if (jnt < 0) return Error{world.scene_path() + ": cubelet '" + name + "' has no joint"};
        c.qpos = m->jnt_qposadr[jnt];
        c.hinge = m->jnt_type[jnt] == mjJNT_HINGE;
        for (int g = m->body_geomadr[c.body]; g < m->body_geomadr[c.body] + m->body_geomnum[c.body]; ++g) {
          const char* gname = mj_id2name(m, mjOBJ_GEOM, g);
          const std::string gn = gname ? gname : "";
          if (gn.rfind("sticker_", 0) == 0) c.stickers.emplace_back(g, gn.back());
        }
        if (c.hinge) {
          const int axis_count = (x != 1) + (y != 1) + (z != 1);
          if (axis_count != 1) return Error{world.scene_path() + ": hinge on non-centre cubelet " + name};
          char face = x == 2 ? 'R' : x == 0 ? 'L' : y == 2 ? 'B' : y == 0 ? 'F' : z == 2 ? 'U' : 'D';
          cube.face_hinge_qpos_[face_index(face)] = c.qpos;
        }
        c.name = name;
        cube.cubelets_.push_back(c);
      }
    }
  }
  // Detent: τ = −k sin(4θ) pulls each face layer toward the nearest multiple of 90°.
  std::array<int, 6> dofs{};
  for (int f = 0; f < 6; ++f) {
    for (int j = 0; j < m->njnt; ++j)
      if (m->jnt_qposadr[j] == cube.face_hinge_qpos_[f]) dofs[f] = m->jnt_dofadr[j];
  }
  const auto qpos = cube.face_hinge_qpos_;
  world.add_step_hook([qpos, dofs, detent](const mjModel_*, mjData_* d) {
    for (int f = 0; f < 6; ++f) {
      const double th = d->qpos[qpos[f]];
      d->qfrc_applied[dofs[f]] = -detent.stiffness * std::sin(4.0 * th) - detent.damping * d->qvel[dofs[f]];
    }
  });
  // Layer locks, when the scene has them (a weld `lock_<cubelet>` per cubelet).
  std::vector<LayerLocks::Piece> pieces;
  for (const Cubelet& c : cube.cubelets_) {
    LayerLocks::Piece p;
    p.body = c.body;
    p.eq = mj_name2id(m, mjOBJ_EQUALITY, ("lock_" + c.name).c_str());
    if (c.hinge) {
      const Vec3 p0(m->body_pos[3 * c.body], m->body_pos[3 * c.body + 1], m->body_pos[3 * c.body + 2]);
      int axis = 0;
      p0.cwiseAbs().maxCoeff(&axis);
      for (int f = 0; f < 6; ++f)
        if (face_axis(kFaces[f]) == std::pair<int, int>{axis, p0[axis] > 0 ? 1 : -1}) p.centre_of = f;
    }
    pieces.push_back(p);
  }
  cube.locks_ = LayerLocks::Create(m, cube.core_, pieces, detent, cube.pitch_);
  if (cube.locks_) {
    mj_forward(m, world.data());
    cube.locks_->lock_all(world.mutable_model(), world.data());
    World* w = &world;
    auto locks = cube.locks_;
    world.add_post_step_hook([w, locks](const mjModel_*, mjData_* d) { locks->after_step(w->mutable_model(), d); });
  }
  return cube;
}

double RubiksCube::face_angle(char face) const {
  const int f = face_index(face);
  return f < 0 ? 0.0 : world_->data()->qpos[face_hinge_qpos_[f]];
}

double RubiksCube::face_misalignment(char face) const {
  const double q = units::kPi / 2;
  const double a = face_angle(face);
  return a - q * std::round(a / q);
}

Pose RubiksCube::core_pose() const { return world_->body_pose(core_); }

char RubiksCube::turning_face() const {
  return locks_ && locks_->turning() >= 0 ? kFaces[locks_->turning()] : 0;
}

int RubiksCube::layer_unlocks() const { return locks_ ? locks_->unlocks() : 0; }

void RubiksCube::lock_in_place() {
  if (locks_) locks_->lock_all(world_->mutable_model(), world_->data());
}

double RubiksCube::layer_twist(char face) const {
  const int f = face_index(face);
  return locks_ && f >= 0 ? locks_->twist()[static_cast<std::size_t>(f)] : 0.0;
}

Vec3 RubiksCube::in_core(const Vec3& p_W) const {
  const Pose X = core_pose();
  return X.inverse() * p_W;
}

std::string RubiksCube::facelets() const {
  const mjData* d = world_->data();
  const Quat R_CW = core_pose().R.conjugate();
  // Facelet grid: for each face, 9 slots indexed by the two in-face coordinates (−1, 0, 1).
  std::string out(54, '?');
  const std::string order = "URFDLB";
  for (const auto& c : cubelets_) {
    for (const auto& [g, colour] : c.stickers) {
      const Vec3 p = in_core(Vec3(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]));
      Mat3 M;
      const double* R = d->geom_xmat + 9 * g;
      M << R[0], R[1], R[2], R[3], R[4], R[5], R[6], R[7], R[8];
      // The sticker is thinnest along its normal: the geom axis with the smallest size.
      const double* size = world_->model()->geom_size + 3 * g;
      int thin = 0;
      for (int k = 1; k < 3; ++k)
        if (size[k] < size[thin]) thin = k;
      const Vec3 n = R_CW * Vec3(M.col(thin));
      int axis = 0;
      n.cwiseAbs().maxCoeff(&axis);
      const Vec3 pos_dir = p;  // the sticker sits on the outside: its position says which side
      const int sign = pos_dir[axis] >= 0 ? 1 : -1;
      char face = '?';
      for (char f : std::string("UDFBRL")) {
        if (face_axis(f) == std::pair<int, int>{axis, sign}) face = f;
      }
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      const int i1 = static_cast<int>(std::lround(p[a1] / pitch_)) + 1;
      const int i2 = static_cast<int>(std::lround(p[a2] / pitch_)) + 1;
      if (i1 < 0 || i1 > 2 || i2 < 0 || i2 > 2) continue;
      const auto fi = order.find(face);
      if (fi == std::string::npos) continue;
      out[fi * 9 + i2 * 3 + i1] = colour;
    }
  }
  return out;
}

bool RubiksCube::is_solved() const {
  const std::string s = facelets();
  for (int f = 0; f < 6; ++f) {
    for (int k = 1; k < 9; ++k) {
      if (s[f * 9 + k] != s[f * 9] || s[f * 9] == '?') return false;
    }
  }
  return true;
}

Status RubiksCube::turn(char face, int quarter_turns) {
  const auto [axis, sign] = face_axis(face);
  if (axis < 0) return Error{std::string("unknown face '") + face + "'; expected one of U D F B R L"};
  const mjModel* m = world_->model();
  mjData* d = world_->data();
  const double angle = sign * quarter_turns * units::kPi / 2;  // about the outward normal
  Vec3 a = Vec3::Zero();
  a[axis] = 1.0;
  const Quat R(Eigen::AngleAxisd(angle, a));
  for (const auto& c : cubelets_) {
    const Vec3 p = in_core(Vec3(d->xpos[3 * c.body], d->xpos[3 * c.body + 1], d->xpos[3 * c.body + 2]));
    if (std::lround(p[axis] / pitch_) != sign) continue;  // not in this layer
    double* q = d->qpos + c.qpos;
    if (c.hinge) {
      q[0] += quarter_turns * units::kPi / 2;  // the hinge axis is the outward normal
    } else {
      const Quat q_old(q[0], q[1], q[2], q[3]);
      const Quat q_new = (R * q_old).normalized();
      q[0] = q_new.w(), q[1] = q_new.x(), q[2] = q_new.y(), q[3] = q_new.z();
    }
  }
  mj_forward(m, d);
  if (locks_) locks_->lock_all(world_->mutable_model(), d);  // every cubelet locked where it now is
  return Ok{};
}

std::string RubiksCube::scramble(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> face(0, 5), turns(1, 3);
  std::string moves;
  char last = 0;
  for (int k = 0; k < n; ++k) {
    char f;
    do f = kFaces[face(rng)];
    while (f == last);
    last = f;
    const int t = turns(rng);
    (void)turn(f, t);
    moves += (moves.empty() ? "" : " ") + std::string(1, f) + (t == 2 ? "2" : t == 3 ? "'" : "");
  }
  return moves;
}

}  // namespace spidar::physics
