#include "spidar/session/cube_monitor.hpp"

#include <cmath>

#include "spidar/core/units.hpp"
#include "spidar/physics/world_reset.hpp"

namespace spidar::session {

namespace {
constexpr char kFaces[6] = {'U', 'D', 'F', 'B', 'R', 'L'};
}

void TurnCounter::rebase(const physics::RubiksCube& cube) {
  for (int f = 0; f < 6; ++f)
    quarter_[f] = static_cast<int>(std::lround(cube.face_angle(kFaces[f]) / (units::kPi / 2)));
}

void TurnCounter::update(const physics::RubiksCube& cube) {
  for (int f = 0; f < 6; ++f) {
    const double a = cube.face_angle(kFaces[f]);
    if (std::abs(cube.face_misalignment(kFaces[f])) > 0.05) continue;
    const int q = static_cast<int>(std::lround(a / (units::kPi / 2)));
    if (q != quarter_[f]) {
      turns_ += std::abs(q - quarter_[f]);
      per_face_[static_cast<std::size_t>(f)] += std::abs(q - quarter_[f]);
      quarter_[f] = q;
    }
  }
}

int TurnCounter::turns_of(char face) const {
  for (int f = 0; f < 6; ++f)
    if (kFaces[f] == face) return per_face_[static_cast<std::size_t>(f)];
  return 0;
}

CubeMonitor::CubeMonitor(std::optional<physics::RubiksCube>* cube, const Pose& X_cube0)
    : cube_(cube), X_cube0_(X_cube0) {}

void CubeMonitor::before_step(physics::World& w) {
  if (reset_.exchange(false, std::memory_order_acq_rel)) {
    physics::reset_world(w);
    if (cube_->has_value()) {
      (*cube_)->lock_in_place();  // the layer locks were set for the cubelets' old places
      turns_.rebase(**cube_);
    }
  }
  if (const int n = scramble_.exchange(0, std::memory_order_acq_rel); n > 0 && cube_->has_value()) {
    (void)(*cube_)->scramble(n, scramble_seed_++);
    turns_.rebase(**cube_);
  }
  CubeStatus s;
  s.t_s = w.time();
  s.contacts = w.contact_count();
  if (cube_->has_value()) {
    const physics::RubiksCube& cube = **cube_;
    const Pose X = cube.core_pose();
    turns_.update(cube);
    pose_.publish({{X.p.x(), X.p.y(), X.p.z()}, {X.R.w(), X.R.x(), X.R.y(), X.R.z()}, turns_.turns_of('U')});
    s.present = true;
    s.lift = X.p.z() - X_cube0_.p.z();
    s.u_angle = cube.face_angle('U');
    s.d_angle = cube.face_angle('D');
    s.turns = turns_.turns();
    s.top_turns = turns_.turns_of('U');
    s.solved = cube.is_solved();
  }
  status_.publish(s);
}

}  // namespace spidar::session
