#include "session_parts.hpp"

#include <algorithm>
#include <cmath>

#include "cli_support.hpp"
#include "spidar/core/units.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/physics/world_reset.hpp"

namespace spidar::app {

vision::Camera scaled_camera(const vision::Camera& c, int w, int h) {
  vision::Intrinsics k = c.intrinsics();
  const double sx = static_cast<double>(w) / k.width, sy = static_cast<double>(h) / k.height;
  k.fx *= sx;
  k.fy *= sy;
  k.cx = (k.cx + 0.5) * sx - 0.5;
  k.cy = (k.cy + 0.5) * sy - 0.5;
  k.width = w;
  k.height = h;
  return vision::Camera(k, c.X_CW());
}

std::array<hand::HandModel, 2> hand_models(const std::string& path, const std::string& profile,
                                           bool first_if_missing) {
  const hand::HandProfiles profiles = hand::load_hand_profiles(path);  // throws ConfigError
  const hand::HandProfile* p = profiles.find(profile);
  if (p == nullptr) {
    if (!first_if_missing || profiles.profiles.empty())
      throw UsageError(path + ": no hand profile '" + profile + "'");
    p = &profiles.profiles.front();
  }
  return {p->model(hand::Side::kLeft), p->model(hand::Side::kRight)};
}

void reach_target(const SceneSnapshot& scene, sim::RubiksTaskParams* tp) {
  double best = 1e9;
  for (const Shape& s : scene.shapes) {
    if (s.body <= 0 || s.hand >= 0) continue;
    const double d = s.X_WS.p.norm();
    if (d < best) {
      best = d;
      tp->p_W_cube = s.X_WS.p;
      tp->half = std::clamp(s.size.maxCoeff(), 0.01, 0.05);
      tp->pitch = tp->half * 2.0 / 3.0;
    }
  }
}

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
      quarter_[f] = q;
    }
  }
}

ServoTiming servo_timing_since(std::span<const device::FingertipSample> s, double rate_hz,
                               std::int64_t* last_t_ns) {
  ServoTiming out;
  int cycles = 0;
  const double nominal_us = 1e6 / rate_hz;
  for (std::size_t k = 0; k + 1 < s.size() && s[k].t_ns > *last_t_ns; ++k) {
    ++cycles;
    out.jitter_max_us = std::max(out.jitter_max_us, std::abs(core::ns_to_s(s[k].t_ns - s[k + 1].t_ns) * 1e6 - nominal_us));
  }
  if (!s.empty() && *last_t_ns > 0 && cycles > 0) out.rate_hz = cycles / core::ns_to_s(s[0].t_ns - *last_t_ns);
  if (!s.empty()) *last_t_ns = s[0].t_ns;
  return out;
}

std::shared_ptr<sim::RubiksTask> make_scripted_task(const physics::World& world,
                                                    const std::optional<physics::RubiksCube>& cube,
                                                    double proxy_radius,
                                                    const std::array<hand::HandModel, 2>& user,
                                                    Pose* X_cube0, double deadline_s) {
  sim::RubiksTaskParams tp;
  tp.proxy_radius = proxy_radius;
  tp.has_cube = cube.has_value();
  if (deadline_s > 0) tp.deadline = deadline_s;
  *X_cube0 = Pose{};
  if (cube) {
    *X_cube0 = cube->core_pose();
    tp.p_W_cube = X_cube0->p;
  } else {
    SceneSnapshot s0;
    world.snapshot(s0, false);
    reach_target(s0, &tp);
    X_cube0->p = tp.p_W_cube;
  }
  auto task = std::make_shared<sim::RubiksTask>(tp);
  task->fit_to_hands(user);
  return task;
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
    pose_.publish({{X.p.x(), X.p.y(), X.p.z()}, {X.R.w(), X.R.x(), X.R.y(), X.R.z()}, turns_.turns()});
    s.lift = X.p.z() - X_cube0_.p.z();
    s.u_angle = cube.face_angle('U');
    s.d_angle = cube.face_angle('D');
    s.turns = turns_.turns();
    s.solved = cube.is_solved();
  }
  status_.publish(s);
}

}  // namespace spidar::app
