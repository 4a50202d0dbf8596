#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/core/thread_name.hpp"

#include <algorithm>
#include <cmath>

#include "spidar/core/clock.hpp"
#include "spidar/core/realtime.hpp"
#include "spidar/core/units.hpp"

namespace spidar::sim {

ProxyFrame proxy_frame(const physics::World& world, int finger_count, std::int64_t t_ns, std::uint64_t step) {
  ProxyFrame frame;
  frame.t_ns = t_ns;
  frame.step = step;
  frame.finger_count = finger_count;
  const auto proxies = world.proxies();
  for (int f = 0; f < finger_count && f < kMaxFingers && f < static_cast<int>(proxies.size()); ++f) {
    frame.p_W[f] = {proxies[f].p_W.x(), proxies[f].p_W.y(), proxies[f].p_W.z()};
    frame.v_W[f] = {proxies[f].v_W.x(), proxies[f].v_W.y(), proxies[f].v_W.z()};
    frame.plane_count[f] = proxies[f].plane_count;
    for (int k = 0; k < proxies[f].plane_count; ++k) {
      const auto& pl = proxies[f].planes[k];
      frame.planes[f][k] = {pl.n_W.x(), pl.n_W.y(), pl.n_W.z(), pl.offset};
    }
  }
  return frame;
}

namespace {

Vec3 vec(const Xyz& a) { return {a[0], a[1], a[2]}; }
Xyz xyz(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

HapticForces::HapticForces(physics::CouplingParams coupling, double servo_rate_hz,
                           bool passivity_control, double velocity_cutoff_hz)
    : coupling_(coupling), dt_(1.0 / servo_rate_hz) {
  const double rc = 1.0 / (2.0 * units::kPi * velocity_cutoff_hz);
  alpha_ = dt_ / (rc + dt_);
  for (auto& p : ports_) p = physics::PassivityPort(passivity_control);
}

void HapticForces::forces(const device::FingertipSample& in, device::ForceFrame& out) noexcept {
  const int n = std::min(in.finger_count, kMaxFingers);
  // Fingertip velocities: finite differences, low-passed.
  const double dt = have_prev_ && in.t_ns > prev_.t_ns ? core::ns_to_s(in.t_ns - prev_.t_ns) : dt_;
  TargetFrame target;
  target.t_ns = in.t_ns;
  target.finger_count = n;
  for (int f = 0; f < n; ++f) {
    const Vec3 p = device::fingertip_position(in, f);
    if (have_prev_) v_[f] += alpha_ * ((p - device::fingertip_position(prev_, f)) / dt - v_[f]);
    target.p_W[f] = xyz(p);
    target.v_W[f] = xyz(v_[f]);
  }
  prev_ = in;
  have_prev_ = true;
  targets_.publish(target);

  out.f_W = {};
  const auto proxies = proxies_.read();
  if (!proxies) {  // physics not started yet: nothing to touch, and not stale
    out.t_ns = in.t_ns;
    return;
  }
  out.t_ns = proxies->t_ns;  // the servo's watchdog judges how fresh the physics is
  const double since = std::max(0.0, core::ns_to_s(in.t_ns - proxies->t_ns));
  for (int f = 0; f < n && f < proxies->finger_count; ++f) {
    physics::ProxyState local;
    local.p_W = vec(proxies->p_W[f]);
    local.v_W = vec(proxies->v_W[f]);
    local.plane_count = proxies->plane_count[f];
    for (int k = 0; k < local.plane_count; ++k) {
      const auto& pl = proxies->planes[f][k];
      local.planes[k] = {Vec3(pl[0], pl[1], pl[2]), pl[3]};
    }
    const Vec3 p_proxy = physics::local_proxy_position(local, std::min(since, 0.01));
    // The user feels the opposite of the coupling force on the proxy.
    const Vec3 f_user = -physics::coupling_force(coupling_, device::fingertip_position(in, f), v_[f],
                                                 p_proxy, local.v_W);
    const Vec3 shown = ports_[f].step(f_user, v_[f], dt);
    stats_.ports[f] = ports_[f].stats();
    out.set_force(f, shown);
  }
}

PhysicsThread::PhysicsThread(physics::World& world, HapticForces& bridge, double rate_hz,
                             int snapshot_every)
    : world_(world),
      bridge_(bridge),
      rate_hz_(rate_hz > 0 ? rate_hz : 1.0 / world.timestep()),
      snapshot_every_(std::max(1, snapshot_every)) {
  step_ms_.reserve(1 << 20);
}

PhysicsThread::~PhysicsThread() { stop(); }

void PhysicsThread::start() {
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void PhysicsThread::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void PhysicsThread::run() {
  core::set_thread_name("spidar-physics");
  if (rt_priority_ > 0) realtime_ = core::set_fifo_priority(rt_priority_).ok();
  const auto n = static_cast<int>(world_.proxies().size());
  std::vector<Vec3> p(n, Vec3::Zero()), v(n, Vec3::Zero());
  const auto period = static_cast<std::int64_t>(1e9 / rate_hz_);
  std::int64_t deadline = core::monotonic_ns();
  t0_ = deadline;
  bool placed = false;
  std::uint64_t step = 0;
  while (!stop_.load(std::memory_order_acquire)) {
    core::sleep_until_ns(deadline);
    const std::int64_t start = core::monotonic_ns();
    if (start - deadline > period) ++late_;
    const auto target = bridge_.targets().read();
    if (target) {
      for (int f = 0; f < n && f < target->finger_count; ++f) {
        p[f] = Vec3(target->p_W[f][0], target->p_W[f][1], target->p_W[f][2]);
        v[f] = Vec3(target->v_W[f][0], target->v_W[f][1], target->v_W[f][2]);
      }
      if (!placed) {
        world_.place_proxies(p);  // start the proxies where the fingertips are
        placed = true;
      }
    }
    if (before_step_) before_step_(world_);
    if (placed) world_.step(p, v);
    const std::int64_t end = core::monotonic_ns();
    step_ms_.push_back(static_cast<double>(end - start) * 1e-6);

    const ProxyFrame frame = proxy_frame(world_, n, end, ++step);
    if (placed) bridge_.proxies().publish(frame);
    if (step % snapshot_every_ == 0) {
      world_.snapshot(snapshots_.back(), snapshot_proxies_);
      snapshots_.publish();
    }
    deadline += period;
    if (end > deadline) deadline = end;  // running slower than asked: no catch-up bursts
    t1_ = end;
  }
}

PhysicsThreadStats PhysicsThread::stats() const {
  PhysicsThreadStats s;
  s.steps = step_ms_.size();
  s.seconds = core::ns_to_s(t1_ - t0_);
  s.rate_hz = s.seconds > 0 ? static_cast<double>(s.steps) / s.seconds : 0;
  if (!step_ms_.empty()) {
    std::vector<double> sorted = step_ms_;
    std::sort(sorted.begin(), sorted.end());
    s.step_ms_median = sorted[sorted.size() / 2];
    s.step_ms_p99 = sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
    s.step_ms_max = sorted.back();
  }
  s.late_steps = late_;
  s.realtime_scheduling = realtime_;
  s.memory = world_.memory_use();
  return s;
}

}  // namespace spidar::sim
