// Hand forward kinematics with both 3D Jacobians (fingertips and all joints), one hand.
// Goal (issue 5): ≤ 5 µs median.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "spidar/hand/kinematics.hpp"

namespace {

using namespace spidar::hand;

std::vector<HandParams> poses(const HandModel& m, int n) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<HandParams> out(n);
  for (auto& p : out) {
    for (int i = 0; i < kParamCount; ++i) {
      const double lo = std::isfinite(m.limits.lower[i]) ? m.limits.lower[i] : -0.5;
      const double hi = std::isfinite(m.limits.upper[i]) ? m.limits.upper[i] : 0.5;
      p.q[i] = lo + (hi - lo) * unit(rng);
    }
  }
  return out;
}

void HandFkJacobians(benchmark::State& state) {
  const HandModel model = default_hand_model(Side::kRight);
  const auto qs = poses(model, 64);
  HandPoints points;
  FingertipJacobian J_tips;
  JointJacobian J_joints;
  std::size_t i = 0;
  for (auto _ : state) {
    forward_kinematics(model, qs[i++ & 63], &points, &J_tips, &J_joints);
    benchmark::DoNotOptimize(points);
    benchmark::DoNotOptimize(J_tips.data());
    benchmark::DoNotOptimize(J_joints.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(HandFkJacobians);

void HandFkOnly(benchmark::State& state) {
  const HandModel model = default_hand_model(Side::kRight);
  const auto qs = poses(model, 64);
  HandPoints points;
  std::size_t i = 0;
  for (auto _ : state) {
    forward_kinematics(model, qs[i++ & 63], &points, nullptr, nullptr);
    benchmark::DoNotOptimize(points);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(HandFkOnly);

}  // namespace
