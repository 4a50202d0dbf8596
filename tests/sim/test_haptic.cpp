#include <gtest/gtest.h>

#include "sanitizer.hpp"
#include "source_path.hpp"

#include <cstdio>
#include <cstring>
#include <new>
#include <thread>

#include "spidar/core/clock.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/scripted_grasp.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::sim {
namespace {

using spidar::test::source;

/// A change of a displayed force between two servo cycles larger than this is a jump [N]. Contact
/// onset is the worst case: the fingertip meets a surface the local model learns of only after
/// the next physics step, so the force can rise by k × (depth reached meanwhile). Measured: 3.2 N
/// on a quiet machine, 5.5 N with the physics thread a few ms late on a loaded one, 8.1 N once in
/// a release `ctest -j2` (2026-11-27), 9.0 N in an ASan run; 1000 N/m × 8 mm.
constexpr double kForceJumpBound = 8.0;
/// How many cycles may jump: one contact onset met after a late physics step is the machine's
/// timing; a rendering that chatters jumps in many cycles.
constexpr int kForceJumpsAllowed = 3;

TEST(Haptic, ScriptedTwoHandScenarioLiftsTurnsAndFeelsContinuous) {
  const auto cfg = strings::load_device_config(source("configs/spidar8.yaml"));
  auto world = physics::World::Load(source("scenes/rubiks_cube.xml")).value();
  auto cube = physics::RubiksCube::Attach(*world).value();
  const Pose X0 = cube.core_pose();
  RubiksScriptParams sp;
  sp.p_W_cube = X0.p;
  auto script = std::make_shared<RubiksScript>(sp);
  device::SimulatedSpidar dev(cfg, {}, script);
  ASSERT_TRUE(dev.open().ok());
  device::ServoConfig servo;
  servo.force_timeout_s = 0.05;
  servo.deadline_periods = 50;  // this test is about haptics; a busy CI machine may be late
  servo.stall_limit_s = 1.0;    // a 0.1 s stall would latch the safe state: no force felt after it
  auto bridge = std::make_shared<HapticForces>(world->params().coupling, servo.rate_hz);
  PhysicsThread physics(*world, *bridge);
  std::atomic<double> lift_max{0};
  physics.set_before_step([&](physics::World&) {
    lift_max.store(std::max(lift_max.load(), cube.core_pose().p.z() - X0.p.z()));
  });
  device::ServoLoop loop(dev, cfg, servo, bridge);
  physics.start();
  ASSERT_TRUE(loop.start().ok());
  std::vector<device::FingertipSample> all, buf(1023);
  std::uint64_t next = 0;
  const auto t0 = core::monotonic_ns();
  while (core::ns_to_s(core::monotonic_ns() - t0) < sp.duration) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto n = loop.newest_samples(buf.data(), buf.size());
    for (std::size_t k = n; k-- > 0;)
      if (buf[k].cycle >= next) all.push_back(buf[k]), next = buf[k].cycle + 1;
  }
  loop.stop();
  physics.stop();

  EXPECT_GT(lift_max.load(), 0.005);
  EXPECT_NEAR(cube.face_angle('U'), 1.5708, 0.035);  // turned one click and snapped
  EXPECT_FALSE(cube.is_solved());
  // Timing faults (a late servo wake-up, a physics thread starved for 50 ms by a loaded machine)
  // are the watchdogs doing their job; anything else is a failure.
  EXPECT_EQ(loop.faults() & ~(device::kFaultDeadlineMiss | device::kFaultWatchdog | device::kFaultForceStall), 0u)
      << device::fault_names(loop.faults());
  std::array<double, 8> fmax{};
  double jump = 0;
  int jumps = 0;  // finger-cycles whose force changed by more than kForceJumpBound
  for (std::size_t k = 0; k < all.size(); ++k) {
    for (int f = 0; f < 8; ++f) {
      const Vec3 F(all[k].f_W[f][0], all[k].f_W[f][1], all[k].f_W[f][2]);
      fmax[f] = std::max(fmax[f], F.norm());
      if (k > 0 && all[k].cycle == all[k - 1].cycle + 1) {
        const double d = (F - Vec3(all[k - 1].f_W[f][0], all[k - 1].f_W[f][1], all[k - 1].f_W[f][2])).norm();
        jump = std::max(jump, d);
        jumps += d > kForceJumpBound ? 1 : 0;
        if (d > kForceJumpBound) std::printf("JUMP cycle %llu finger %d d %.2f F %.2f\n", (unsigned long long)all[k].cycle, f, d, F.norm());
      }
    }
  }
  for (int f = 0; f < 8; ++f) EXPECT_GT(fmax[f], 0.5) << "finger " << f << " felt nothing";
  RecordProperty("force_jump_max_n", std::to_string(jump));
  RecordProperty("force_jumps", std::to_string(jumps));
  // Continuity is a real-time property: how large the one worst step is depends on how late the
  // physics thread was at a contact's onset, so the release build asserts that the force does
  // not jump repeatedly (chatter); under a sanitizer (the physics thread several times slower,
  // starved on a busy machine) it is reported.
  if (!test::kUnderSanitizer) EXPECT_LE(jumps, kForceJumpsAllowed) << "largest " << jump << " N";
  else if (jumps > kForceJumpsAllowed) std::printf("%d force jumps, largest %.2f N (not asserted under a sanitizer)\n", jumps, jump);
  // Enough consecutive samples to judge the force profile (at least a second of them): how many
  // a real-time run collects is a matter of speed (5734 of ~7000 in an ASan build), not tested.
  EXPECT_GT(all.size(), 1000u);
}

/// A fingertip (human impedance) pressing on the fixed block through the coupling at 1 kHz, the
/// servo side rendering against the local model. Returns the lowest energy the observer saw [J]
/// and the peak-to-peak force over the last 0.2 s [N].
struct SweepResult {
  double min_energy = 0, ripple = 0;
  bool finite = true;
};
SweepResult press(double stiffness, bool control) {
  physics::WorldParams wp;
  wp.proxy.count = 1;
  wp.coupling.stiffness = stiffness;
  wp.coupling.damping = 2.0;
  wp.coupling.max_force = 1e6;  // no cap: let instability show
  auto w = physics::World::Load(source("scenes/blocks.xml"), wp).value();
  const Vec3 top(0.12, 0.08, 0.01), goal = top + Vec3(0, 0, 0.008 - 0.004);
  Vec3 x = top + Vec3(0, 0, 0.02), v = Vec3::Zero();
  std::vector<Vec3> p{x}, vv{v};
  w->place_proxies(p);
  physics::PassivityPort port(control);
  const double dt = 0.001, m = 0.015, kf = 300, bf = 1.0;
  SweepResult r;
  double fmin = 1e9, fmax = -1e9;
  for (int k = 0; k < 3000; ++k) {
    p[0] = x;
    vv[0] = v;
    w->step(p, vv);
    physics::ProxyState ps = w->proxies()[0];
    const Vec3 f_user = -physics::coupling_force(wp.coupling, x, v, physics::local_proxy_position(ps, 0.0), ps.v_W);
    const Vec3 f = port.step(f_user, v, dt);
    // The finger is continuous; the device holds the force over the servo period (zero-order
    // hold). Integrate it in fine sub-steps, as the simulated device does.
    for (int sub = 0; sub < 8; ++sub) {
      const double h = dt / 8;
      v += h * (kf * (goal - x) - bf * v + f) / m;
      x += h * v;
    }
    if (!x.allFinite() || x.norm() > 10) {
      r.finite = false;
      break;
    }
    if (k > 2800) fmin = std::min(fmin, f.z()), fmax = std::max(fmax, f.z());
  }
  r.min_energy = port.stats().min_energy;
  r.ripple = r.finite ? fmax - fmin : 1e9;
  return r;
}

// The fingertips' filtered velocities start at zero whatever the bridge's memory held before:
// they are the coupling's damping input and the physics' proxy velocities. (They were left to
// Eigen's default constructor, which does not initialise: heap garbage, filtered on from there,
// made 12–18 N force spikes in the scenario test above in a build whose heap layout differed.)
TEST(Haptic, TheBridgeStartsFromRestWhateverItsMemoryHeld) {
  alignas(HapticForces) unsigned char memory[sizeof(HapticForces)];
  std::memset(memory, 0x7f, sizeof memory);  // each double 1.4e306: finite, and far from zero
  auto* bridge = new (memory) HapticForces(physics::CouplingParams{}, 1000.0);
  device::FingertipSample sample;
  sample.finger_count = 8;
  for (int f = 0; f < 8; ++f) sample.p_W[f] = {0.01 * f, 0.0, 0.02};
  device::ForceFrame force;
  for (int cycle = 0; cycle < 2; ++cycle) {  // the first cycle, and the first filtered one
    sample.t_ns = 1000000 * cycle;
    bridge->forces(sample, force);
    const auto target = bridge->targets().read();
    ASSERT_TRUE(target.has_value());
    for (int f = 0; f < 8; ++f)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(target->v_W[f][k], 0.0) << "cycle " << cycle << ", finger " << f;
  }
  bridge->~HapticForces();
}

TEST(Haptic, PressingAFixedBlockDisplaysTheCouplingForceWithinTensionLimits) {
  // The right middle finger (its unit pulls toward the back-top corner, so it can push a
  // fingertip up) presses 6 mm into the fixed block; the servo side renders k·depth upward and
  // the strings display it within their limits.
  const auto cfg = strings::load_device_config(source("configs/spidar8.yaml"));
  physics::WorldParams wp;
  wp.proxy.count = 1;
  auto w = physics::World::Load(source("scenes/blocks.xml"), wp).value();
  const Vec3 top(0.12, 0.08, 0.01);
  std::vector<Vec3> p{top + Vec3(0, 0, 0.02)}, v{Vec3::Zero()};
  w->place_proxies(p);
  p[0] = top + Vec3(0, 0, wp.proxy.radius - 0.006);
  for (int k = 0; k < 500; ++k) w->step(p, v);
  physics::ProxyState ps = w->proxies()[0];
  const Vec3 f_user = -physics::coupling_force(wp.coupling, p[0], Vec3::Zero(),
                                               physics::local_proxy_position(ps, 0.0), ps.v_W);
  EXPECT_NEAR(f_user.z(), wp.coupling.stiffness * 0.006, 0.3);
  const auto& finger = cfg.fingers[6];  // right_middle
  const auto lim = cfg.effective_limits();
  const auto sol = strings::solve_tensions(finger.geometry, p[0], f_user, lim).value();
  for (int i = 0; i < sol.t.size(); ++i) {
    EXPECT_GE(sol.t[i], lim.t_min);
    EXPECT_LE(sol.t[i], lim.t_max);
  }
  // The displayed force is the nearest the strings can show: pushing up along the desired force.
  EXPECT_GT(sol.f_displayed.dot(f_user.normalized()), 0.0);
}

TEST(Haptic, DISABLED_PrintSweep) {
  for (double k : {500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0, 4000.0, 6000.0, 10000.0}) {
    const auto a = press(k, false), b = press(k, true);
    std::printf("k=%6.0f  open: finite %d ripple %.4f minE %.5f | controlled: finite %d ripple %.4f minE %.6f\n", k, a.finite, a.ripple, a.min_energy, b.finite, b.ripple, b.min_energy);
  }
}

TEST(Haptic, StiffnessSweepStableUpToTheDocumentedLimitObserverCatchesBeyond) {
  // Documented limit (README): without control the coupling settles up to 2 kN/m (a 1 ms servo,
  // a 15 g fingertip with 1 N·s/m, coupling damping 2 N·s/m; Colgate's b > kT/2 bound is ~6 kN/m)
  // with only a little energy generated at contact onset; it diverges from 4 kN/m.
  for (double k : {500.0, 1000.0, 2000.0}) {
    const auto r = press(k, false);
    EXPECT_TRUE(r.finite) << k;
    EXPECT_LT(r.ripple, 0.05) << "k=" << k << " still oscillating";
    EXPECT_GT(r.min_energy, -0.02) << "k=" << k;
  }
  // Beyond: unstable, and the observer sees the port go active.
  const auto bad = press(6000.0, false);
  EXPECT_TRUE(!bad.finite || bad.ripple > 0.5);
  EXPECT_LT(bad.min_energy, -1.0);
  // The passivity controller keeps the port passive and bounded where the open loop diverges.
  const auto controlled = press(6000.0, true);
  EXPECT_TRUE(controlled.finite);
  EXPECT_GT(controlled.min_energy, -1e-4);
  EXPECT_LT(controlled.ripple, 20.0);
}

}  // namespace
}  // namespace spidar::sim
