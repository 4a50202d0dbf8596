#include "spidar/session/truth_scorer.hpp"

#include <algorithm>
#include <cmath>

#include "spidar/core/clock.hpp"
#include "spidar/core/units.hpp"
#include "spidar/session/scripted_task.hpp"

namespace spidar::session {

TruthScorer::TruthScorer(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth_models,
                         const pipeline::FramePipelineParams& params)
    : camera_(camera), truth_models_(truth_models), skin_(params.model_skin), mode_(params.compositor.mode) {}

TruthScorer::~TruthScorer() {
  // Normally released in on_end on the scorer's thread; here (a run that failed) the context is
  // made current on this thread first by the renderer's own destructor.
  ceiling_.reset();
  context_.reset();
}

void TruthScorer::on_start() {
  auto ctx = render::Context::create_headless();
  if (!ctx) throw SpidarError("ground truth: OpenGL: " + ctx.error().message);
  context_ = std::move(ctx).value();
  // The model's ceiling: its own skin at the user's true pose and sizes (every compared frame).
  auto c = sim::ModelCeiling::create(*context_, camera_, truth_models_, skin_);
  if (!c) throw SpidarError(c.error().message);
  ceiling_ = std::move(c).value();
  // One ceiling drawn before the clock starts and thrown away: the GL driver compiles its shaders
  // at the first draw (the first compared frame's scoring took 39 ms instead of 2).
  const cv::Mat none = cv::Mat::zeros(camera_.height(), camera_.width(), CV_8UC1);
  if (auto w = ceiling_->iou({hand::HandParams{}, hand::HandParams{}}, none, {}); !w)
    throw SpidarError("ground truth: warm-up: " + w.error().message);
}

void TruthScorer::on_end(const SessionSummary&) {
  ceiling_.reset();
  context_.reset();
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
  const auto camera_index = static_cast<std::int64_t>(filmed.index);
  m.dropped_before = static_cast<int>(std::max<std::int64_t>(0, camera_index - last_camera_index_ - 1));
  last_camera_index_ = camera_index;
  // The simulated camera reads a frame's ground-truth images after handing over its image.
  const sim::SyntheticFrame& images = filmed.wait_for_truth_images();
  const std::int64_t t_scoring_ns = core::monotonic_ns();
  auto main_m = sim::measure_frame(images, result, mode_, result.models, truth_models_, filmed.truth,
                                   camera_, &ws_);
  if (!main_m) throw SpidarError(main_m.error().message);
  m.truth[0] = *main_m;
  if (e.compared != nullptr) {
    auto alt_m = sim::measure_frame(images, *e.compared, mode_, e.compared->models, truth_models_,
                                    filmed.truth, camera_, &ws_);
    if (!alt_m) throw SpidarError(alt_m.error().message);
    m.truth[1] = *alt_m;
    m.compared = true;
    if (!ceiling_) throw SpidarError("ground truth: a frame before on_start (no GL context)");
    // Its own context, current here whatever else this thread renders (Session::step makes the
    // frame thread's current again before the next frame).
    if (auto st = context_->make_current(); !st) throw SpidarError("ground truth: " + st.error().message);
    auto c = ceiling_->iou(filmed.truth, images.hand_only, images.toward_elbow_W, images.hand_id, &m.ceiling_loss);
    if (!c) throw SpidarError(c.error().message);
    m.ceiling_iou = *c;
    m.ceiling_measured = true;
  }
  for (int h = 0; h < 2; ++h) {
    m.iterations[h] = result.fits[h].iterations;
    m.shape[h] = result.shapes[h];
    m.truth_cap_residual_mm[h] = filmed.cap_residual_m[h] * 1e3;
  }
  if (const auto& s = e.cube; s && s->present) {
    m.lift_mm = s->lift * 1e3;
    m.u_angle_deg = s->u_angle * 180 / units::kPi;
    m.d_angle_deg = s->d_angle * 180 / units::kPi;
    m.turns = s->top_turns;
  } else if (e.scene != nullptr) {
    const std::vector<Shape>& shapes = e.scene->shapes;
    if (object_shape_ < 0)
      if (const Shape* o = nearest_object(*e.scene)) {
        object_shape_ = o - shapes.data();
        object_z0_m_ = o->X_WS.p.z();
      }
    if (object_shape_ >= 0 && static_cast<std::size_t>(object_shape_) < shapes.size())
      m.lift_mm = (shapes[static_cast<std::size_t>(object_shape_)].X_WS.p.z() - object_z0_m_) * 1e3;
  }
  for (int f = 0; f < 8; ++f) {
    const auto& F = e.measured->f_W[f];
    m.force_n[f] = Vec3(F[0], F[1], F[2]).norm();
  }
  m.servo_rate_hz = e.servo.rate_hz;
  m.servo_jitter_max_us = e.servo.jitter_max_us;
  // The comparison fit (on the frame thread) and this scoring (wherever it runs).
  m.truth_ms = e.compare_ms + core::ns_to_s(core::monotonic_ns() - t_scoring_ns) * 1e3;
  trace_.frames.push_back(m);
}

void TruthScorer::set_output_ms(double ms) {
  if (!trace_.frames.empty()) trace_.frames.back().output_ms = ms;
}

}  // namespace spidar::session
