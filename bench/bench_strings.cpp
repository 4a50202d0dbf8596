// String-device maths per fingertip: position from lengths and tension distribution, on the
// SPIDAR-8 (3 strings) and SPIDAR-G4 (4 strings) layouts, against generic reference solvers.
// Each iteration solves one fingertip, cycling through 1024 random workspace problems.
#include <benchmark/benchmark.h>

#include <random>

#include "reference_tension.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace {

using namespace spidar;
using namespace spidar::strings;

const DeviceConfig& config(int strings) {
  static const DeviceConfig s8 = load_device_config(std::string(SPIDAR_SOURCE_DIR) + "/configs/spidar8.yaml");
  static const DeviceConfig g4 = load_device_config(std::string(SPIDAR_SOURCE_DIR) + "/configs/spidar-g4.yaml");
  return strings == 3 ? s8 : g4;
}

struct Problem {
  const PointGeometry* g;
  StringVec lengths;
  Vec3 p;
  StringMat U;
  Vec3 force;
};

/// Random fingertips within 12 cm of the centre on the inner side; lengths with 0.1 mm noise
/// (4 strings: the least-squares path); forces of up to 20 N, half inside the force cone.
std::vector<Problem> problems(int strings) {
  const auto& cfg = config(strings);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-0.12, 0.12), w(0.4, 10.0);
  std::normal_distribution<double> noise(0, 1e-4), n(0, 8.0);
  std::vector<Problem> out;
  while (out.size() < 1024) {
    const auto& g = cfg.fingers[out.size() % cfg.fingers.size()].geometry;
    const Vec3 p(u(rng), u(rng), u(rng));
    if (g.triple.n3_inner.dot(p - g.triple.p_WA1) < 0.02) continue;
    Problem pr{&g, string_lengths(g, p), p, string_directions(g, p).value(), Vec3(n(rng), n(rng), n(rng))};
    if (strings > 3)
      for (int i = 0; i < g.n; ++i) pr.lengths[i] += noise(rng);
    if (out.size() % 2 == 0) {
      pr.force.setZero();
      for (int i = 0; i < g.n; ++i) pr.force += w(rng) * pr.U.col(i);
    }
    out.push_back(pr);
  }
  return out;
}

void BM_Position(benchmark::State& state, int strings) {
  const auto ps = problems(strings);
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& pr = ps[k++ & 1023];
    auto est = solve_position(*pr.g, std::span<const double>(pr.lengths.data(), pr.g->n));
    benchmark::DoNotOptimize(est);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("per fingertip");
}

void BM_Tension(benchmark::State& state, int strings) {
  const auto ps = problems(strings);
  const auto lim = config(strings).effective_limits();
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& pr = ps[k++ & 1023];
    auto sol = solve_tensions(pr.U, pr.force, lim);
    benchmark::DoNotOptimize(sol);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel("per fingertip");
}

/// Including the string directions from the fingertip position (what the servo loop pays).
void BM_TensionFromPosition(benchmark::State& state, int strings) {
  const auto ps = problems(strings);
  const auto lim = config(strings).effective_limits();
  std::size_t k = 0;
  for (auto _ : state) {
    const auto& pr = ps[k++ & 1023];
    auto sol = solve_tensions(*pr.g, pr.p, pr.force, lim);
    benchmark::DoNotOptimize(sol);
  }
  state.SetItemsProcessed(state.iterations());
}

/// Generic reference: accelerated projected gradient to a 1e-10 N step (dynamic Eigen).
void BM_TensionReferenceProjectedGradient(benchmark::State& state, int strings) {
  const auto ps = problems(strings);
  const auto lim = config(strings).effective_limits();
  std::vector<Eigen::MatrixXd> Us;
  for (const auto& pr : ps) Us.emplace_back(pr.U);
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t i = k++ & 1023;
    auto ref = reference::projected_gradient_tensions(Us[i], ps[i].force, lim.t_min, lim.t_max, 1e-10);
    benchmark::DoNotOptimize(ref);
  }
  state.SetItemsProcessed(state.iterations());
}

/// Brute-force reference: every active set (3^N) with SVD pseudo-inverses.
void BM_TensionReferenceBruteForce(benchmark::State& state, int strings) {
  const auto ps = problems(strings);
  const auto lim = config(strings).effective_limits();
  std::vector<Eigen::MatrixXd> Us;
  for (const auto& pr : ps) Us.emplace_back(pr.U);
  std::size_t k = 0;
  for (auto _ : state) {
    const std::size_t i = k++ & 1023;
    auto ref = reference::brute_force_tensions(Us[i], ps[i].force, lim.t_min, lim.t_max);
    benchmark::DoNotOptimize(ref);
  }
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK_CAPTURE(BM_Position, Position3, 3)->Name("Position3");
BENCHMARK_CAPTURE(BM_Position, Position4, 4)->Name("Position4");
BENCHMARK_CAPTURE(BM_Tension, Tension3, 3)->Name("Tension3");
BENCHMARK_CAPTURE(BM_Tension, Tension4, 4)->Name("Tension4");
BENCHMARK_CAPTURE(BM_TensionFromPosition, 3, 3)->Name("Tension3FromPosition");
BENCHMARK_CAPTURE(BM_TensionFromPosition, 4, 4)->Name("Tension4FromPosition");
BENCHMARK_CAPTURE(BM_TensionReferenceProjectedGradient, 3, 3)->Name("Tension3RefProjectedGradient");
BENCHMARK_CAPTURE(BM_TensionReferenceProjectedGradient, 4, 4)->Name("Tension4RefProjectedGradient");
BENCHMARK_CAPTURE(BM_TensionReferenceBruteForce, 3, 3)->Name("Tension3RefBruteForce");
BENCHMARK_CAPTURE(BM_TensionReferenceBruteForce, 4, 4)->Name("Tension4RefBruteForce");

}  // namespace

BENCHMARK_MAIN();
