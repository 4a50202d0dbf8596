// The frame pipeline for one 640x480 frame (chroma key, bracelets, registration of both hands,
// render of the Rubik's cube scene with the fitted hands, the composite): the frame thread's
// cost per camera frame, without the simulation's own costs (synthetic camera, ground truth).
// The software GL renders in the drawing thread, as in the app (render::render_in_drawing_thread).
#include <benchmark/benchmark.h>

#include <chrono>

#include "spidar/hand/hand_config.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/context.hpp"
#include "spidar/sim/camera_thread.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/sim/user_hands.hpp"
#include "spidar/vision/vision_config.hpp"

namespace {

using namespace spidar;

std::string source(const std::string& rel) { return std::string(SPIDAR_SOURCE_DIR) + "/" + rel; }

/// Args: the silhouette term (0/1); the other compositor's picture too (0: the demo's frame
/// thread, which leaves it to the output thread; 1: the library's default).
void FramePipeline640x480(benchmark::State& state) {
  render::render_in_drawing_thread();
  auto ctx = render::Context::create_headless();
  if (!ctx) {
    state.SkipWithError(ctx.error().message.c_str());
    return;
  }
  const auto profiles = hand::load_hand_profiles(source("configs/hands.yaml"));
  const auto* user = profiles.find("user");
  const std::array<hand::HandModel, 2> truth{user->model(hand::Side::kLeft), user->model(hand::Side::kRight)};
  const std::array<hand::HandModel, 2> models{hand::default_hand_model(hand::Side::kLeft),
                                              hand::default_hand_model(hand::Side::kRight)};
  const vision::Camera camera = vision::default_rig_camera();
  auto world = physics::World::Load(source("scenes/rubiks_cube.xml")).value();
  SceneSnapshot scene;
  world->snapshot(scene, false);
  sim::RubiksTaskParams tp;
  sim::RubiksTask task(tp);
  sim::UserHands hands(truth, task);
  std::array<Vec3, 8> g;
  task.goals(3.0, g);  // both hands holding the lifted cube
  hands.update(3.0, g);
  auto film = sim::SyntheticCamera::create(*ctx.value(), camera, truth).value();
  sim::SyntheticFrame frame;
  const auto& q = hands.params();
  (void)film->film({&q[0], &q[1]}, &frame);
  device::FingertipSample tips;
  tips.finger_count = 8;
  for (int f = 0; f < 8; ++f) tips.p_W[f] = {g[f].x(), g[f].y(), g[f].z()};
  const auto vc = vision::load_vision_config(source("configs/vision.yaml"));
  pipeline::FramePipelineParams p;
  p.chroma_key = vc.chroma_key;
  p.bracelet = vc.bracelet;
  p.registration.silhouette_term = state.range(0) != 0;
  p.other_composite = state.range(1) != 0;
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] = task.nominal(3.0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  auto pipe = pipeline::FramePipeline::create(*ctx.value(), camera, models, p).value();
  pipeline::FrameResult r;
  for (int k = 0; k < 5; ++k) (void)pipe->process(frame.bgr, tips, scene, &r);  // settle
  double key = 0, bracelets = 0, distance = 0, reg = 0, render = 0, composite = 0;
  for (auto _ : state) {
    if (auto st = pipe->process(frame.bgr, tips, scene, &r); !st) {
      state.SkipWithError(st.error().message.c_str());
      break;
    }
    key += r.timings.key_ms;
    bracelets += r.timings.bracelet_ms;
    distance += r.timings.distance_ms;
    reg += r.timings.registration_ms;
    render += r.timings.render_ms;
    composite += r.timings.composite_ms;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["key_ms"] = key / n;
  state.counters["bracelet_ms"] = bracelets / n;
  state.counters["distance_ms"] = distance / n;
  state.counters["registration_ms"] = reg / n;
  state.counters["render_ms"] = render / n;
  state.counters["composite_ms"] = composite / n;
  // The other compositor's picture of the same result, as the demo's output thread makes it
  // (session::AsyncSinks::compose_others).
  if (!p.other_composite) {
    render::Compositor other(pipeline::other_compositor_params(p.compositor));
    cv::Mat image, alpha;
    const auto t0 = std::chrono::steady_clock::now();
    constexpr int kOther = 20;
    for (int k = 0; k < kOther; ++k) (void)pipeline::compose_result(other, r, frame.bgr, &image, &alpha);
    state.counters["other_composite_ms"] =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / kOther;
  }
}
BENCHMARK(FramePipeline640x480)
    ->ArgNames({"silhouette", "other"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

/// A deep copy of one frame's result at 640×480 (pipeline::copy_frame_result: eleven images into
/// buffers of the right size): what handing a result to the output thread cost per frame before the
/// session shared it from a pool instead (session.hpp, FrameEvent::result_hold).
void CopyFrameResult640x480(benchmark::State& state) {
  pipeline::FrameResult from, to;
  const cv::Size size(640, 480);
  from.key.alpha = cv::Mat(size, CV_32FC1, cv::Scalar(0.5));
  from.key.silhouette = cv::Mat(size, CV_8UC1, cv::Scalar(255));
  from.key.foreground = cv::Mat(size, CV_8UC3, cv::Scalar::all(90));
  from.virt.colour = cv::Mat(size, CV_8UC3, cv::Scalar::all(60));
  from.virt.depth = cv::Mat(size, CV_32FC1, cv::Scalar(0.6));
  from.virt.hand_depth = cv::Mat(size, CV_32FC1, cv::Scalar(0.55));
  from.virt.hand_id = cv::Mat(size, CV_8UC1, cv::Scalar(3));
  from.composite = cv::Mat(size, CV_8UC3, cv::Scalar::all(70));
  from.composite_alpha = cv::Mat(size, CV_32FC1, cv::Scalar(0.25));
  from.other = cv::Mat(size, CV_8UC3, cv::Scalar::all(80));
  from.other_alpha = cv::Mat(size, CV_32FC1, cv::Scalar(0.75));
  pipeline::copy_frame_result(from, &to);  // the buffers exist, as they do after the first frame
  for (auto _ : state) {
    pipeline::copy_frame_result(from, &to);
    benchmark::DoNotOptimize(to.composite.data);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(CopyFrameResult640x480)->Unit(benchmark::kMillisecond);

/// A deep copy of one filmed frame at 640×480 and of its camera image (sim::copy_filmed_frame and
/// the image's copyTo, into buffers of the right size): what handing the simulated camera's frame
/// to the output thread cost per frame before the camera shared it from a pool instead
/// (sim::CameraThread::shared, FrameEvent::filmed_hold).
void CopyFilmedFrame640x480(benchmark::State& state) {
  sim::FilmedFrame from, to;
  const cv::Size size(640, 480);
  from.frame.bgr = cv::Mat(size, CV_8UC3, cv::Scalar::all(60));
  from.frame.mask = cv::Mat(size, CV_8UC1, cv::Scalar(255));
  from.frame.hand_index = cv::Mat(size, CV_8UC1, cv::Scalar(1));
  from.frame.hand_only = cv::Mat(size, CV_8UC1, cv::Scalar(255));
  from.frame.depth = cv::Mat(size, CV_32FC1, cv::Scalar(0.5));
  cv::Mat image;
  sim::copy_filmed_frame(from, &to);  // the buffers exist, as they do after the first frame
  from.frame.bgr.copyTo(image);
  for (auto _ : state) {
    sim::copy_filmed_frame(from, &to);
    from.frame.bgr.copyTo(image);
    benchmark::DoNotOptimize(to.frame.depth.data);
    benchmark::DoNotOptimize(image.data);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(CopyFilmedFrame640x480)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
