// The camera side of one frame: chroma key + both bracelets + distance transform with labels on
// a 640×480 frame (two drawn hands over an unevenly lit blue screen). Goal (issue 5): ≤ 2 ms
// median on the 2-core development machine. The parts are also timed alone.
#include <benchmark/benchmark.h>

#include "../tests/vision/synthetic_scene.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/chroma_key.hpp"
#include "spidar/vision/lens_undistortion.hpp"
#include "spidar/vision/silhouette.hpp"

namespace {

using namespace spidar::vision;

const cv::Mat& frame() {
  static const cv::Mat f =
      test::draw_scene({test::DrawnHand{{190, 400}, -1.75, 170}, test::DrawnHand{{450, 390}, -1.35, 170}})
          .bgr;
  return f;
}

// Arguments: the distance transform's margin around the silhouette [px] (0 = whole image) and
// its downsampling (1 = full resolution, 2 = half).
void VisionFrame(benchmark::State& state) {
  const auto keyer = ChromaKeyer::create(ChromaKeyParams{}).value();
  const BraceletParams bp;
  ChromaKeyResult matte;
  BraceletWorkspace ws;
  SilhouetteDistance dist;
  const SilhouetteDistanceOptions dt{static_cast<int>(state.range(0)), static_cast<int>(state.range(1))};
  for (auto _ : state) {
    if (!keyer.apply(frame(), &matte).ok()) state.SkipWithError("chroma key failed");
    auto wrists = detect_bracelets(frame(), bp, nullptr, &ws);
    if (!wrists.ok() || !(*wrists)[0].found) state.SkipWithError("bracelet not found");
    if (!silhouette_distance(matte.silhouette, &dist, dt).ok()) state.SkipWithError("dt failed");
    benchmark::DoNotOptimize(dist.label_pixel.data());
  }
}
BENCHMARK(VisionFrame)->Args({0, 1})->Args({48, 1})->Args({48, 2})->Unit(benchmark::kMillisecond);

void ChromaKeyOnly(benchmark::State& state) {
  const auto keyer = ChromaKeyer::create(ChromaKeyParams{}).value();
  ChromaKeyResult matte;
  for (auto _ : state) {
    benchmark::DoNotOptimize(keyer.apply(frame(), &matte).ok());
  }
}
BENCHMARK(ChromaKeyOnly)->Unit(benchmark::kMillisecond);

// A frame through a webcam's barrel lens (k1 −0.28, k2 0.09) undistorted into its pinhole camera,
// as a session does on the frame thread before the pipeline (LensUndistortion::undistort); and
// the maps' construction, once per calibration (arg 1).
Intrinsics webcam() {
  Intrinsics k;
  k.distortion = {-0.28, 0.09, 0.0008, -0.0005, 0.0};
  return k;
}
void LensUndistort(benchmark::State& state) {
  const auto lens = LensUndistortion::create(webcam()).value();
  cv::Mat out;
  for (auto _ : state) {
    lens.undistort(frame(), &out);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(LensUndistort)->Unit(benchmark::kMillisecond);
void LensUndistortionCreate(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(LensUndistortion::create(webcam()).ok());
}
BENCHMARK(LensUndistortionCreate)->Unit(benchmark::kMillisecond);

void BraceletsOnly(benchmark::State& state) {
  BraceletWorkspace ws;
  for (auto _ : state) {
    benchmark::DoNotOptimize(detect_bracelets(frame(), BraceletParams{}, nullptr, &ws).ok());
  }
}
BENCHMARK(BraceletsOnly)->Unit(benchmark::kMillisecond);

void DistanceTransformOnly(benchmark::State& state) {
  ChromaKeyResult matte;
  (void)chroma_key(frame(), ChromaKeyParams{}, &matte);
  SilhouetteDistance dist;
  for (auto _ : state) {
    const SilhouetteDistanceOptions dt{static_cast<int>(state.range(0)), static_cast<int>(state.range(1))};
    benchmark::DoNotOptimize(silhouette_distance(matte.silhouette, &dist, dt).ok());
  }
}
BENCHMARK(DistanceTransformOnly)->Args({0, 1})->Args({48, 1})->Args({48, 2})->Unit(benchmark::kMillisecond);

void RedMaskOnly(benchmark::State& state) {
  cv::Mat mask;
  for (auto _ : state) {
    benchmark::DoNotOptimize(red_mask(frame(), BraceletParams{}, &mask).ok());
  }
}
BENCHMARK(RedMaskOnly)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
