// The simulated user's per-frame cost: UserHands::update, the inverse kinematics that poses the
// truth hands on the device's caps before the synthetic camera films them (run on the camera
// thread for every exposure, so it adds to the demo's latency). Measured over the whole script at
// the camera's 30 fps, caps at the script's goals, as the camera thread calls it.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>

#include "spidar/hand/hand_config.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/user_hands.hpp"

namespace {

using namespace spidar;

std::string source(const std::string& rel) { return std::string(SPIDAR_SOURCE_DIR) + "/" + rel; }

/// One iteration: one update at the next frame's time (the script replayed from its start when
/// done). Counters: the caps' mean residual after the update [mm], mean and max over the frames.
void UserHandsUpdate30fps(benchmark::State& state) {
  const auto profiles = hand::load_hand_profiles(source("configs/hands.yaml"));
  const auto* user = profiles.find("user");
  const std::array<hand::HandModel, 2> truth{user->model(hand::Side::kLeft), user->model(hand::Side::kRight)};
  sim::RubiksTask task({});
  task.fit_to_hands(truth);
  const int frames = static_cast<int>(task.params().duration * 30.0);
  auto hands = std::make_unique<sim::UserHands>(truth, task);
  std::array<Vec3, 8> caps;
  int k = 0;
  double residual_sum = 0, residual_max = 0;
  std::int64_t n = 0;
  for (auto _ : state) {
    if (k == frames) {
      state.PauseTiming();
      hands = std::make_unique<sim::UserHands>(truth, task);  // the script again, from a cold start
      k = 0;
      state.ResumeTiming();
    }
    const double t = k / 30.0;
    task.goals(t, caps);
    hands->update(t, caps);
    const auto r = hands->cap_residual_m();
    const double worst = std::max(r[0], r[1]) * 1e3;
    residual_sum += worst;
    residual_max = std::max(residual_max, worst);
    ++n;
    ++k;
  }
  state.counters["cap_residual_mm_mean"] = residual_sum / static_cast<double>(std::max<std::int64_t>(n, 1));
  state.counters["cap_residual_mm_max"] = residual_max;
}
BENCHMARK(UserHandsUpdate30fps)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
