// Physics step of the Rubik's cube scene with all eight proxies pressing on the cube, and the
// servo-side haptic cycle with physics decoupled (local proxy model, passivity control, tensions).
#include <benchmark/benchmark.h>

#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/sim/haptic_bridge.hpp"
#include "spidar/sim/scripted_grasp.hpp"

namespace {

using namespace spidar;

std::string source(const std::string& rel) { return std::string(SPIDAR_SOURCE_DIR) + "/" + rel; }

/// Targets of the scripted grasp at t (all fingers pressing on the cube during the turn).
std::vector<Vec3> grasp_targets(const Vec3& c, double t) {
  sim::RubiksScriptParams p;
  p.p_W_cube = c;
  sim::RubiksScript script(p);
  std::vector<Vec3> g(8);
  script.goals(t, g);
  return g;
}

void BM_PhysicsStepCube8Proxies(benchmark::State& state) {
  auto w = physics::World::Load(source("scenes/rubiks_cube.xml")).value();
  auto cube = physics::RubiksCube::Attach(*w).value();
  const Vec3 c = cube.core_pose().p;
  std::vector<Vec3> v(8, Vec3::Zero());
  w->place_proxies(grasp_targets(c, 0.0));
  // Settle into the grasp first (2 s of the script), then time steps while the layer turns.
  double t = 0;
  for (; t < 2.0; t += w->timestep()) w->step(grasp_targets(c, t), v);
  std::vector<std::vector<Vec3>> targets;
  for (int k = 0; k < 2000; ++k) targets.push_back(grasp_targets(c, 3.0 + k * 0.001));
  std::size_t k = 0;
  int contacts = 0;
  for (auto _ : state) {
    w->step(targets[k++ % targets.size()], v);
    contacts += w->contact_count();
  }
  state.counters["contacts"] = benchmark::Counter(contacts, benchmark::Counter::kAvgIterations);
}

void BM_HapticCycleDecoupled(benchmark::State& state) {
  const auto cfg = strings::load_device_config(source("configs/spidar8.yaml"));
  auto w = physics::World::Load(source("scenes/rubiks_cube.xml")).value();
  auto cube = physics::RubiksCube::Attach(*w).value();
  auto script = std::make_shared<sim::RubiksScript>(sim::RubiksScriptParams{cube.core_pose().p});
  device::SimulatedSpidarParams dp;
  dp.fixed_step_s = 0.001;
  device::SimulatedSpidar dev(cfg, dp, script);
  (void)dev.open();
  dev.clear_safe_state();
  device::ServoCycle cycle(cfg, dev.info());
  sim::HapticForces bridge(w->params().coupling, 1000.0);
  // One physics step's worth of proxies in contact, published as the physics thread would.
  std::vector<Vec3> v(8, Vec3::Zero());
  w->place_proxies(grasp_targets(cube.core_pose().p, 2.0));
  for (int k = 0; k < 200; ++k) w->step(grasp_targets(cube.core_pose().p, 2.0), v);
  sim::ProxyFrame frame;
  frame.finger_count = 8;
  for (int f = 0; f < 8; ++f) {
    const auto& p = w->proxies()[f];
    frame.p_W[f] = {p.p_W.x(), p.p_W.y(), p.p_W.z()};
    frame.plane_count[f] = p.plane_count;
    for (int j = 0; j < p.plane_count; ++j)
      frame.planes[f][j] = {p.planes[j].n_W.x(), p.planes[j].n_W.y(), p.planes[j].n_W.z(), p.planes[j].offset};
  }
  std::vector<std::int32_t> commands(24);
  device::EncoderReading reading;
  device::FingertipSample sample;
  device::ForceFrame force;
  for (auto _ : state) {
    (void)dev.read(reading);
    cycle.measure(reading, sample);
    frame.t_ns = sample.t_ns;
    bridge.proxies().publish(frame);
    bridge.forces(sample, force);
    cycle.command(force, false, sample, commands);
    (void)dev.write(commands);
    ++sample.cycle;
  }
  state.SetLabel("device read + positions + local model + passivity + tensions + write");
}

BENCHMARK(BM_PhysicsStepCube8Proxies)->Name("PhysicsStepCube8Proxies")->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HapticCycleDecoupled)->Name("HapticCycleDecoupled")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
