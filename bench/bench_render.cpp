// Rendering on this machine's GL (Mesa llvmpipe when headless). Goals (issue 6) at 640×480:
// scene + hands render (with read-back of all targets) ≤ 8 ms median; compositor ≤ 3 ms;
// synthetic camera frame ≤ 10 ms. Argument: image width (640 → 640×480, 1280 → 1280×720).
#include <benchmark/benchmark.h>

#include <iostream>

#include "../tests/render/synthetic_hands.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/render/composite_metrics.hpp"
#include "spidar/render/compositor.hpp"
#include "spidar/render/context.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/vision/chroma_key.hpp"

namespace {

using namespace spidar;

render::Context* context() {
  static std::unique_ptr<render::Context> ctx = [] {
    render::render_in_drawing_thread();  // as the app renders
    auto r = render::Context::create_headless();
    if (!r) {
      std::cerr << "bench_render: " << r.error().message << "\n";
      return std::unique_ptr<render::Context>();
    }
    std::cerr << "bench_render: GL_RENDERER " << (*r)->gl_renderer() << "\n";
    return std::move(r).value();
  }();
  return ctx.get();
}

vision::Camera camera(int width) {
  vision::Camera cam = vision::default_rig_camera();
  if (width == 640) return cam;
  vision::Intrinsics K = cam.intrinsics();
  const double s = width / 640.0;
  K.width = width;
  K.height = width * 9 / 16;
  K.fx *= s;
  K.fy *= s;
  K.cx = (K.width - 1) / 2.0;
  K.cy = (K.height - 1) / 2.0;
  cam.set_intrinsics(K);
  return cam;
}

/// The cube scene (physics snapshot) with both model hands.
SceneSnapshot cube_scene_with_hands() {
  auto world = physics::World::Load(std::string(SPIDAR_SOURCE_DIR) + "/scenes/rubiks_cube.xml");
  SceneSnapshot s;
  if (!world) {
    std::cerr << "bench_render: " << world.error().message << "\n";
    return s;
  }
  (*world)->snapshot(s);
  const auto q = render::test::reaching_hands();
  for (int h = 0; h < 2; ++h)
    render::append_hand_shapes(
        hand::hand_render_shapes(hand::default_hand_model(static_cast<hand::Side>(h)), q[h]), &s);
  return s;
}

void RenderSceneAndHands(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const vision::Camera cam = camera(static_cast<int>(state.range(0)));
  const SceneSnapshot scene = cube_scene_with_hands();
  auto renderer = render::Renderer::create(*context(), cam.width(), cam.height()).value();
  render::RenderTargets t;
  for (auto _ : state) {
    if (!renderer->render(scene, cam).ok() || !renderer->read(&t).ok())
      state.SkipWithError("render failed");
    benchmark::DoNotOptimize(t.colour.data);
  }
  state.counters["shapes"] = static_cast<double>(scene.shapes.size());
}
BENCHMARK(RenderSceneAndHands)->Arg(640)->Arg(1280)->Unit(benchmark::kMillisecond);

/// Where the raster time goes at 640×480 (all four targets read back): the scene split by part.
/// Arg 0: everything; 1: without the static world (shapes of body 0, the table); 2: the static
/// world only; 3: the hands only; 4: the moving objects only (no hands, no world).
void RenderScenePart(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const vision::Camera cam = camera(640);
  const SceneSnapshot full = cube_scene_with_hands();
  SceneSnapshot scene = full;
  const auto part = state.range(0);
  scene.shapes.clear();
  for (const Shape& sh : full.shapes) {
    const bool hand = sh.hand >= 0, world = !hand && sh.body <= 0;
    const bool keep = part == 0 || (part == 1 && !world) || (part == 2 && world) ||
                      (part == 3 && hand) || (part == 4 && !hand && !world);
    if (keep) scene.shapes.push_back(sh);
  }
  auto renderer = render::Renderer::create(*context(), cam.width(), cam.height()).value();
  render::RenderTargets t;
  for (auto _ : state) {
    if (!renderer->render(scene, cam).ok() || !renderer->read(&t).ok())
      state.SkipWithError("render failed");
  }
  state.counters["shapes"] = static_cast<double>(scene.shapes.size());
}
BENCHMARK(RenderScenePart)->DenseRange(0, 4)->Unit(benchmark::kMillisecond);

/// Render + read-back of one target at 640×480 (arg: 0 nothing but a 1-target sync read of hand id,
/// 1 colour, 2 depth, 3 hand depth, 4 hand id): where the read-back's time goes.
void RenderReadOne(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const vision::Camera cam = camera(640);
  const SceneSnapshot scene = cube_scene_with_hands();
  auto renderer = render::Renderer::create(*context(), cam.width(), cam.height()).value();
  render::RenderTargets t;
  const unsigned which[] = {render::kHandId, render::kColour, render::kDepth, render::kHandDepth, render::kHandId};
  const auto k = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    if (!renderer->render(scene, cam).ok() || !renderer->read(&t, which[k]).ok())
      state.SkipWithError("render failed");
  }
}
BENCHMARK(RenderReadOne)->DenseRange(1, 4)->Unit(benchmark::kMillisecond);

/// An empty scene at 640×480, rendered and read back (arg as RenderReadOne; 5: all four): the
/// fixed cost of the targets' clears and read-back, whatever the scene holds.
void RenderEmpty(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const vision::Camera cam = camera(640);
  const SceneSnapshot scene;
  auto renderer = render::Renderer::create(*context(), cam.width(), cam.height()).value();
  render::RenderTargets t;
  const unsigned which[] = {render::kHandId, render::kColour, render::kDepth, render::kHandDepth, render::kHandId,
                            render::kAllTargets};
  const auto k = static_cast<std::size_t>(state.range(0));
  for (auto _ : state) {
    if (!renderer->render(scene, cam).ok() || !renderer->read(&t, which[k]).ok())
      state.SkipWithError("render failed");
  }
}
BENCHMARK(RenderEmpty)->Arg(4)->Arg(5)->Unit(benchmark::kMillisecond);

struct CompositeFixture {
  render::RenderTargets targets;
  vision::ChromaKeyResult key;
  sim::SyntheticFrame frame;
};

CompositeFixture make_composite_inputs(int width) {
  CompositeFixture f;
  const vision::Camera cam = camera(width);
  const SceneSnapshot scene = cube_scene_with_hands();
  auto renderer = render::Renderer::create(*context(), cam.width(), cam.height()).value();
  (void)renderer->render(scene, cam);
  (void)renderer->read(&f.targets);
  auto camera_sim = sim::SyntheticCamera::create(*context(), cam, render::test::truth_models()).value();
  const auto q = render::test::reaching_hands(0.003);  // the model is 3 mm off
  (void)camera_sim->film({&q[0], &q[1]}, &f.frame);
  (void)vision::chroma_key(f.frame.bgr, vision::ChromaKeyParams{}, &f.key);
  return f;
}

void Composite(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const CompositeFixture f = make_composite_inputs(static_cast<int>(state.range(0)));
  render::CompositorParams p;
  p.mode = state.range(1) == 0 ? render::CompositeMode::kDepth : render::CompositeMode::kPaper;
  render::Compositor compositor(p);
  cv::Mat out;
  const render::CompositeInputs in{&f.targets,
                                   p.mode == render::CompositeMode::kDepth ? f.key.foreground
                                                                           : f.frame.bgr,
                                   f.key.alpha};
  for (auto _ : state) {
    if (!compositor.compose(in, &out).ok()) state.SkipWithError("compose failed");
    benchmark::DoNotOptimize(out.data);
  }
  state.SetLabel(render::composite_mode_name(p.mode));
}
BENCHMARK(Composite)->Args({640, 0})->Args({640, 1})->Args({1280, 0})->Unit(benchmark::kMillisecond);

/// The ground truth's occlusion count at 640×480 (render/composite_metrics.hpp): one call over the
/// whole frame, as the truth scorer makes four per frame (whole hand and contested pixels, both
/// compositors).
void RegionDisagreement640(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const CompositeFixture f = make_composite_inputs(640);
  cv::Mat truth;
  (void)render::truth_composite_mask(f.frame.mask, f.frame.depth, f.targets.depth, &truth);
  long wrong = 0;
  for (auto _ : state) {
    auto d = render::region_disagreement(f.key.alpha, truth, f.frame.mask);
    if (!d) state.SkipWithError("region_disagreement failed");
    else wrong += d->wrong;
    benchmark::DoNotOptimize(wrong);
  }
}
BENCHMARK(RegionDisagreement640)->Unit(benchmark::kMicrosecond);

void SyntheticCameraFrame(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  const vision::Camera cam = camera(static_cast<int>(state.range(0)));
  sim::SyntheticCameraParams p;
  p.motion_blur_samples = static_cast<int>(state.range(1));
  auto camera_sim = sim::SyntheticCamera::create(*context(), cam, render::test::truth_models(), p).value();
  const auto q = render::test::reaching_hands(), prev = render::test::reaching_hands(-0.01);
  const sim::HandPoses before = {&prev[0], &prev[1]};
  sim::SyntheticFrame frame;
  for (auto _ : state) {
    if (!camera_sim->film({&q[0], &q[1]}, &frame, p.motion_blur_samples > 1 ? &before : nullptr).ok())
      state.SkipWithError("film failed");
    benchmark::DoNotOptimize(frame.bgr.data);
  }
}
BENCHMARK(SyntheticCameraFrame)->Args({640, 1})->Args({1280, 1})->Args({640, 4})
    ->Unit(benchmark::kMillisecond);

/// The simulated camera's frame in its two parts at 640×480 (arg 0: the image, what the camera
/// thread publishes; 1: then its ground-truth images, read after the publication).
void SyntheticCameraParts(benchmark::State& state) {
  if (!context()) return state.SkipWithError("no headless GL");
  auto camera_sim = sim::SyntheticCamera::create(*context(), camera(640), render::test::truth_models()).value();
  const auto q = render::test::reaching_hands();
  sim::SyntheticFrame frame;
  const bool truth = state.range(0) == 1;
  for (auto _ : state) {
    if (truth) {
      state.PauseTiming();
      if (!camera_sim->film_image({&q[0], &q[1]}, &frame).ok()) state.SkipWithError("film failed");
      state.ResumeTiming();
      if (!camera_sim->film_truth(&frame).ok()) state.SkipWithError("film failed");
    } else {
      if (!camera_sim->film_image({&q[0], &q[1]}, &frame).ok()) state.SkipWithError("film failed");
    }
    benchmark::DoNotOptimize(frame.bgr.data);
  }
}
BENCHMARK(SyntheticCameraParts)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
