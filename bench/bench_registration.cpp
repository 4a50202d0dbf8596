// Successive adjustment of BOTH hands for one camera frame, warm-started from a slightly
// perturbed truth (±3 mm, ±0.03 rad, joints ±0.05 rad: a tracker's frame-to-frame motion), with
// image evidence from one synthetic frame computed once (chroma key, bracelets, distance
// transform). Arg 0: the paper's terms (fingertips, wrist, joint-balls, prior); arg 1: plus the
// silhouette term. Goal: ≤ 2 ms per frame for both hands.
#include <benchmark/benchmark.h>

#include <array>
#include <memory>
#include <random>
#include <vector>

#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/registration/forearm_from_band.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/render/context.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/chroma_key.hpp"
#include "spidar/vision/silhouette.hpp"

namespace {

using namespace spidar;

struct Frame {
  vision::Camera camera = vision::default_rig_camera();
  std::array<hand::HandModel, 2> models{hand::default_hand_model(hand::Side::kLeft),
                                        hand::default_hand_model(hand::Side::kRight)};
  std::array<hand::HandParams, 2> truth;
  vision::ChromaKeyResult key;
  vision::SilhouetteDistance distance;
  std::array<registration::HandObservation, 2> obs;
  std::array<vision::BraceletObservation, 2> bands;
  std::vector<std::array<hand::HandParams, 2>> starts;
  bool ok = false;
};

hand::HandParams reaching_right() {
  hand::HandParams q;
  q.set_wrist(Vec3(0.11, -0.05, 0.04), Vec3(0.05, -0.1, 1.05));
  q[hand::kThumbCmcFlexion] = 0.3;
  q[hand::kThumbCmcAbduction] = 0.45;
  q[hand::kThumbIp] = 0.35;
  q[hand::kIndexMcpFlexion] = 0.45;
  q[hand::kMiddleMcpFlexion] = 0.55;
  q[hand::kRingMcpFlexion] = 0.6;
  q[hand::kIndexMcpAbduction] = 0.08;
  q[hand::kRingMcpAbduction] = 0.05;
  q[hand::kIndexDip] = 0.4;
  q[hand::kMiddleDip] = 0.5;
  q[hand::kRingDip] = 0.55;
  return q;
}

const Frame& frame() {
  static const std::unique_ptr<Frame> f = [] {
    auto fr = std::make_unique<Frame>();
    render::render_in_drawing_thread();  // as the app renders
    auto ctx = render::Context::create_headless();
    if (!ctx) return fr;
    const auto profiles = hand::load_hand_profiles(SPIDAR_SOURCE_DIR "/configs/hands.yaml");
    const hand::HandProfile* user = profiles.find("user");
    if (!user) return fr;
    const std::array<hand::HandModel, 2> truth_models{user->model(hand::Side::kLeft),
                                                      user->model(hand::Side::kRight)};
    fr->truth = {hand::mirror_params(reaching_right()), reaching_right()};
    auto cam = sim::SyntheticCamera::create(**ctx, fr->camera, truth_models);
    if (!cam) return fr;
    sim::SyntheticFrame shot;
    if (!(*cam)->film({&fr->truth[0], &fr->truth[1]}, &shot).ok()) return fr;
    if (!vision::chroma_key(shot.bgr, vision::ChromaKeyParams{}, &fr->key).ok()) return fr;
    vision::SilhouetteDistanceOptions opt;
    opt.max_distance_px = 40;
    if (!vision::silhouette_distance(fr->key.silhouette, &fr->distance, opt).ok()) return fr;
    vision::BraceletWorkspace ws;
    auto bracelets = vision::detect_bracelets(shot.bgr, vision::BraceletParams{}, nullptr, &ws);
    if (!bracelets) return fr;
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.0005);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int h = 0; h < 2; ++h) {
      const hand::HandPoints p = hand::forward_kinematics(truth_models[h], fr->truth[h]);
      for (int i = 0; i < hand::kFingertipCount; ++i) {
        fr->obs[h].p_W_fingertip[i] = p.p_W_fingertip[i] + Vec3(noise(rng), noise(rng), noise(rng));
        fr->obs[h].fingertip_valid[i] = true;
      }
      fr->bands[h] = (*bracelets)[h];
      if ((*bracelets)[h].found) {
        fr->obs[h].wrist_px = (*bracelets)[h].wrist_px;
        fr->obs[h].wrist_confidence = (*bracelets)[h].confidence;
      }
    }
    for (int k = 0; k < 16; ++k) {
      std::array<hand::HandParams, 2> s = fr->truth;
      for (int h = 0; h < 2; ++h) {
        for (int i = 0; i < 6; ++i) s[h][i] += (i < 3 ? 0.003 : 0.03) * u(rng);
        for (int i = hand::kThumbCmcFlexion; i < hand::kParamCount; ++i) s[h][i] += 0.05 * u(rng);
        s[h] = hand::clamp_to_limits(s[h], fr->models[h].limits);
      }
      fr->starts.push_back(s);
    }
    fr->ok = true;
    return fr;
  }();
  return *f;
}

void RegistrationBothHands(benchmark::State& state) {
  const Frame& f = frame();
  if (!f.ok) return state.SkipWithError("no headless GL or synthetic frame");
  registration::RegistrationParams params;
  params.silhouette_term = state.range(0) != 0;
  params.little_free = state.range(1) != 0;  // with the silhouette term: 20 parameters, else 17
  const registration::SuccessiveAdjustment solver(params);
  registration::ImageEvidence image;
  image.camera = &f.camera;
  image.alpha = f.key.alpha;
  image.distance = &f.distance;
  std::size_t k = 0;
  long iterations = 0, fits = 0;
  for (auto _ : state) {
    const auto& start = f.starts[k++ & 15];
    for (int h = 0; h < 2; ++h) {
      hand::HandParams q = start[h];
      const auto rep = solver.fit(f.models[h], f.obs[h], image, &start[h], &q);
      iterations += rep.iterations;
      ++fits;
      benchmark::DoNotOptimize(q.q.data());
    }
    benchmark::ClobberMemory();
  }
  state.counters["iterations_per_hand"] =
      fits ? static_cast<double>(iterations) / static_cast<double>(fits) : 0.0;
}
// The forearms' bend from both bands (registration/forearm_from_band.hpp: every candidate bend's
// band predicted and compared), as the pipeline runs it before the fits with forearm_from_band.
void ForearmFromBandBothHands(benchmark::State& state) {
  const Frame& f = frame();
  if (!f.ok) return state.SkipWithError("no headless GL or synthetic frame");
  if (!f.bands[0].found || !f.bands[1].found) return state.SkipWithError("a bracelet was not found");
  registration::RegistrationParams params;
  params.forearm_from_band = true;
  for (auto _ : state) {
    for (int h = 0; h < 2; ++h) {
      const vision::BraceletObservation& b = f.bands[h];
      const registration::BandObservation band{b.end_a_px, b.end_b_px, b.length_px, b.thickness_px, b.fill};
      const Vec3 last(0.0, -1.0, 0.0);
      auto d = registration::forearm_from_band(hand::hand_pose(f.truth[h]), f.models[h].shape.dimensions.width,
                                               f.camera, params, band, &last);
      benchmark::DoNotOptimize(d);
    }
  }
}
BENCHMARK(ForearmFromBandBothHands)->Unit(benchmark::kMicrosecond);

BENCHMARK(RegistrationBothHands)
    ->ArgNames({"silhouette", "little_free"})
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
