// The simulated rig's per-frame costs. SilhouetteLoss640x480: the IoU's loss split by hand and
// part, which the truth scorer counts two or three times a frame (the fit, the comparison and the
// ceiling), on two hands' worth of pixels. UserHandsUpdate30fps: the simulated user's per-frame cost: UserHands::update, the inverse kinematics that poses the
// truth hands on the device's caps before the synthetic camera films them (run on the camera
// thread for every exposure, so it adds to the demo's latency). Measured over the whole script at
// the camera's 30 fps, caps at the script's goals, as the camera thread calls it.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>

#include <opencv2/imgproc.hpp>

#include "spidar/hand/hand_config.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/sim/silhouette_loss.hpp"
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

/// One iteration: one frame's loss, two hands (palm discs and digit bars) drawn a few pixels apart
/// in the model's and the real image.
void SilhouetteLoss640x480(benchmark::State& state) {
  cv::Mat model(480, 640, CV_8UC1, cv::Scalar(0)), real(480, 640, CV_8UC1, cv::Scalar(0));
  for (int h = 0; h < 2; ++h) {
    const int x0 = 180 + 280 * h;
    const auto palm = render::encode_hand_id(h, render::kPalmPart), digit = render::encode_hand_id(h, 1);
    cv::circle(real, {x0, 300}, 70, palm, cv::FILLED);
    cv::rectangle(real, cv::Rect(x0 - 60, 150, 120, 90), digit, cv::FILLED);
    cv::circle(model, {x0 + 4, 303}, 72, palm, cv::FILLED);
    cv::rectangle(model, cv::Rect(x0 - 55, 148, 112, 92), digit, cv::FILLED);
  }
  sim::SilhouetteLoss loss;
  for (auto _ : state) {
    if (!sim::silhouette_loss(model, real, &loss).ok()) state.SkipWithError("silhouette_loss failed");
    benchmark::DoNotOptimize(loss);
  }
  state.counters["iou"] = loss.iou();
}
BENCHMARK(SilhouetteLoss640x480)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
