// One servo cycle for the eight SPIDAR-8 fingers with the simulated device and no physics:
// read (simulated encoders), counts → positions, forces → tensions → commands, write.
#include <benchmark/benchmark.h>

#include "spidar/device/force_source.hpp"
#include "spidar/device/servo_cycle.hpp"
#include "spidar/device/simulated_spidar.hpp"

namespace {

using namespace spidar;
using namespace spidar::device;

const strings::DeviceConfig& config() {
  static const auto cfg =
      strings::load_device_config(std::string(SPIDAR_SOURCE_DIR) + "/configs/spidar8.yaml");
  return cfg;
}

std::shared_ptr<FingertipSource> hovering() {
  return std::make_shared<ScriptedFingertips>(hovering_hands(rest_points(config())));
}

/// Forces of a few newtons in varying directions, so the tension solver does real work.
struct Pushing final : ForceSource {
  void forces(const FingertipSample& in, ForceFrame& out) noexcept override {
    out.t_ns = in.t_ns;
    const double c = static_cast<double>(in.cycle % 97) / 97.0;
    for (int f = 0; f < 8; ++f) out.set_force(f, Vec3(2.0 * c - 1.0, 1.5 - 3.0 * c, 2.0 + f * 0.1));
  }
};

template <bool kWithDevice, bool kWithForce>
void BM_ServoCycle(benchmark::State& state) {
  SimulatedSpidarParams params;
  params.fixed_step_s = 0.25e-3;  // one 4 kHz cycle of simulated time per read
  SimulatedSpidar sim(config(), params, hovering());
  if (!sim.open().ok()) state.SkipWithError("open failed");
  sim.clear_safe_state();
  ServoCycle cycle(config(), sim.info());
  ZeroForce zero;
  Pushing pushing;
  ForceSource& force = kWithForce ? static_cast<ForceSource&>(pushing) : zero;
  std::vector<std::int32_t> commands(24, sim.info().command_min);
  EncoderReading reading;
  (void)sim.read(reading);
  FingertipSample sample;
  ForceFrame frame;
  for (auto _ : state) {
    if (kWithDevice) (void)sim.read(reading);
    cycle.measure(reading, sample);
    force.forces(sample, frame);
    cycle.command(frame, false, sample, commands);
    if (kWithDevice) (void)sim.write(commands);
    ++sample.cycle;
    benchmark::DoNotOptimize(commands.data());
  }
  state.SetLabel("8 fingers, 24 strings");
}

BENCHMARK(BM_ServoCycle<true, false>)->Name("ServoCycleSimZeroForce");
BENCHMARK(BM_ServoCycle<true, true>)->Name("ServoCycleSimForces");
BENCHMARK(BM_ServoCycle<false, true>)->Name("ServoCycleComputeOnlyForces");

}  // namespace

BENCHMARK_MAIN();
