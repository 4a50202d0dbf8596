#include "spidar/session/truth_scorer.hpp"

#include <cmath>

#include "spidar/core/clock.hpp"
#include "spidar/core/units.hpp"

namespace spidar::session {

TruthScorer::TruthScorer(render::Context& context, const vision::Camera& camera,
                         const std::array<hand::HandModel, 2>& models,
                         const std::array<hand::HandModel, 2>& truth_models,
                         const pipeline::FramePipelineParams& params, CubeMonitor& monitor)
    : camera_(camera), models_(models), truth_models_(truth_models),
      mode_(params.compositor.mode), monitor_(monitor) {
  // The model's ceiling: its own skin at the user's true pose and sizes (every compared frame).
  auto c = sim::ModelCeiling::create(context, camera, truth_models, params.model_skin);
  if (!c) throw SpidarError(c.error().message);
  ceiling_ = std::move(c).value();
}

void TruthScorer::on_frame(const FrameEvent& e) {
  if (e.filmed == nullptr) throw SpidarError("ground truth: a frame without it (not the simulated camera)");
  const sim::FilmedFrame& filmed = *e.filmed;
  const pipeline::FrameResult& result = *e.result;
  TruthFrame m;
  m.t_s = e.t_s;
  m.latency_ms = core::ns_to_s(e.t_done_ns - e.t_exposure_ns) * 1e3;
  m.pipeline_ms = result.timings.total_ms;
  m.registration_ms = result.timings.registration_ms;
  m.preprocess_ms = result.timings.key_ms + result.timings.bracelet_ms + result.timings.distance_ms;
  m.stages = result.timings;
  m.film_ms = filmed.film_ms;
  auto main_m = sim::measure_frame(filmed.frame, result, mode_, result.models, truth_models_, filmed.truth,
                                   camera_, &ws_);
  if (!main_m) throw SpidarError(main_m.error().message);
  m.truth[0] = *main_m;
  if (e.compared != nullptr) {
    auto alt_m = sim::measure_frame(filmed.frame, *e.compared, mode_, e.compared->models, truth_models_,
                                    filmed.truth, camera_, &ws_);
    if (!alt_m) throw SpidarError(alt_m.error().message);
    m.truth[1] = *alt_m;
    m.compared = true;
    auto c = ceiling_->iou(filmed.truth, filmed.frame.hand_only);
    if (!c) throw SpidarError(c.error().message);
    m.ceiling_iou = *c;
    m.ceiling_measured = true;
  }
  for (int h = 0; h < 2; ++h) {
    m.iterations[h] = result.fits[h].iterations;
    m.shape[h] = result.shapes[h];
    m.truth_cap_residual_mm[h] = filmed.cap_residual_m[h] * 1e3;
  }
  if (auto s = monitor_.status().read()) {
    m.lift_mm = s->lift * 1e3;
    m.u_angle_deg = s->u_angle * 180 / units::kPi;
    m.d_angle_deg = s->d_angle * 180 / units::kPi;
    m.turns = s->turns;
  }
  for (int f = 0; f < 8; ++f) {
    const auto& F = e.measured->f_W[f];
    m.force_n[f] = Vec3(F[0], F[1], F[2]).norm();
  }
  m.servo_rate_hz = e.servo.rate_hz;
  m.servo_jitter_max_us = e.servo.jitter_max_us;
  m.truth_ms = core::ns_to_s(core::monotonic_ns() - e.t_done_ns) * 1e3;
  trace_.frames.push_back(m);
}

void TruthScorer::set_output_ms(double ms) {
  if (!trace_.frames.empty()) trace_.frames.back().output_ms = ms;
}

}  // namespace spidar::session
