#pragma once
/// Couples the servo loop (device rate, ≥ 1 kHz) to the physics world (its own thread, its own
/// rate), so the haptic rate does not depend on how costly the scene is.
///
///   servo thread:   FingertipSample ──► HapticForces::forces ──► TargetFrame (Latest) ──┐
///                   displayed force ◄── local model of each proxy ◄── ProxyFrame (Latest) │
///   physics thread: PhysicsThread: TargetFrame ─► World::step ─► ProxyFrame, snapshots ◄─┘
///
/// Between physics steps the servo renders the coupling force against a local model: the proxy's
/// last position, moved with its velocity and held outside its contact planes. A passivity
/// controller per finger adds damping whenever the port would turn active.
#include <array>
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "spidar/core/scene_snapshot.hpp"
#include "spidar/core/seqlock.hpp"
#include "spidar/core/triple_buffer.hpp"
#include "spidar/device/force_source.hpp"
#include "spidar/physics/passivity.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::sim {

using device::kMaxFingers;
using Xyz = std::array<double, 3>;

/// Where the device says the fingertips are (servo → physics).
struct TargetFrame {
  std::int64_t t_ns = 0;
  int finger_count = 0;
  std::array<Xyz, kMaxFingers> p_W{};  ///< [m]
  std::array<Xyz, kMaxFingers> v_W{};  ///< [m/s], filtered
};

/// The proxies after a physics step (physics → servo).
struct ProxyFrame {
  std::int64_t t_ns = 0;  ///< host time of the step
  std::uint64_t step = 0;
  int finger_count = 0;
  std::array<Xyz, kMaxFingers> p_W{}, v_W{};
  std::array<int, kMaxFingers> plane_count{};
  std::array<std::array<std::array<double, 4>, physics::kMaxPlanes>, kMaxFingers> planes{};  ///< n, offset
};

/// The frame the physics thread publishes after a step: the world's first `finger_count` proxies
/// (positions [m], velocities [m/s] and contact planes, world) at host time `t_ns`, step `step`.
ProxyFrame proxy_frame(const physics::World& world, int finger_count, std::int64_t t_ns, std::uint64_t step);

struct HapticStats {
  std::array<physics::PassivityStats, kMaxFingers> ports{};
};

/// The servo loop's force source when a physics world is attached.
class HapticForces final : public device::ForceSource {
 public:
  HapticForces(physics::CouplingParams coupling, double servo_rate_hz, bool passivity_control = true,
               double velocity_cutoff_hz = 100.0);
  void forces(const device::FingertipSample& in, device::ForceFrame& out) noexcept override;

  core::Latest<TargetFrame>& targets() { return targets_; }
  core::Latest<ProxyFrame>& proxies() { return proxies_; }
  /// Passivity statistics; read after the servo loop has stopped.
  HapticStats stats() const { return stats_; }

 private:
  physics::CouplingParams coupling_;
  double dt_;
  double alpha_;  ///< velocity low-pass coefficient
  bool have_prev_ = false;
  device::FingertipSample prev_;
  std::array<Vec3, kMaxFingers> v_ = zeros<Vec3, kMaxFingers>();  ///< filtered fingertip velocities [m/s], world
  std::array<physics::PassivityPort, kMaxFingers> ports_;
  HapticStats stats_;
  core::Latest<TargetFrame> targets_;
  core::Latest<ProxyFrame> proxies_;
};

struct PhysicsThreadStats {
  std::uint64_t steps = 0;
  double seconds = 0;
  double rate_hz = 0;
  double step_ms_median = 0, step_ms_p99 = 0, step_ms_max = 0;
  std::uint64_t late_steps = 0;  ///< steps that started after their deadline
  bool realtime_scheduling = false;  ///< SCHED_FIFO was asked for and granted
  physics::World::MemoryUse memory;  ///< MuJoCo's memory the run used (World::memory_use)
};

/// Steps the world in its own thread at up to `rate_hz` (1/timestep by default), toward the
/// latest targets, publishing proxies every step and a scene snapshot every `snapshot_every`.
/// `before_step` runs in the physics thread before each step (scenario scripting, metrics).
class PhysicsThread {
 public:
  PhysicsThread(physics::World& world, HapticForces& bridge, double rate_hz = 0,
                int snapshot_every = 33);
  ~PhysicsThread();
  void start();
  void stop();
  void set_before_step(std::function<void(physics::World&)> fn) { before_step_ = std::move(fn); }
  /// SCHED_FIFO priority of the physics thread (0 = normal scheduling; set before start()). With
  /// rendering threads competing for the CPUs, a real-time physics thread keeps world time in
  /// step with the user (below the servo loop's 80). Falls back to normal with a warning.
  void set_realtime_priority(int priority) { rt_priority_ = priority; }
  /// Whether snapshots show the fingertip proxies (default yes; set before start()).
  void set_snapshot_proxies(bool on) { snapshot_proxies_ = on; }
  /// Renderer side: true and the newest snapshot in `snapshots().front()` if there is a new one.
  core::TripleBuffer<SceneSnapshot>& snapshots() { return snapshots_; }
  /// Complete once stopped.
  PhysicsThreadStats stats() const;

 private:
  void run();
  physics::World& world_;
  HapticForces& bridge_;
  double rate_hz_;
  int snapshot_every_;
  std::function<void(physics::World&)> before_step_;
  bool snapshot_proxies_ = true;
  int rt_priority_ = 0;
  bool realtime_ = false;
  core::TripleBuffer<SceneSnapshot> snapshots_;
  std::vector<double> step_ms_;
  std::int64_t t0_ = 0, t1_ = 0;
  std::uint64_t late_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace spidar::sim
