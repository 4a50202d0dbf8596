#pragma once
/// The ground-truth scorer: on the simulated rig, every processed frame measured against what
/// the synthetic camera filmed (sim::measure_frame), the comparison fit and the model's ceiling
/// on compared frames, the cube, forces and servo timing — the per-frame trace the demo's report
/// is made of.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "spidar/hand/hand_model.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/render/context.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/model_ceiling.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

struct TruthFrame {
  double t_s = 0;              ///< script time of the exposure [s]
  double latency_ms = 0;       ///< exposure → composite ready [ms]
  double pipeline_ms = 0;      ///< frame pipeline cost [ms]
  double registration_ms = 0;  ///< both hands [ms]
  double preprocess_ms = 0;    ///< chroma key, bracelets, distance transform [ms]
  pipeline::FrameTimings stages;  ///< the main pipeline's stages [ms]
  double film_ms = 0;          ///< synthetic camera (simulation cost, not pipeline) [ms]
  double truth_ms = 0;         ///< ground-truth posture, comparison fit, metrics [ms]
  double output_ms = 0;        ///< video and keyframes [ms]
  /// Camera exposures missing just before this one: delivered but not processed (the frame thread
  /// was still busy) or not filmed in time by the simulated camera; the first frame counts those
  /// since the camera started.
  int dropped_before = 0;
  /// [0]: the main registration, [1]: the comparison (silhouette term switched the other way).
  std::array<sim::FrameTruthMetrics, 2> truth{};
  bool compared = false;  ///< truth[1] measured in this frame
  /// The model's skin at the true pose with the user's sizes vs the real silhouette
  /// (sim::ModelCeiling); measured on compared frames (ceiling_measured).
  double ceiling_iou = 0;
  sim::SilhouetteLoss ceiling_loss;  ///< where the ceiling's skin and the real hands differ
  bool ceiling_measured = false;
  std::array<int, 2> iterations{};
  /// The registration's size estimates after this frame (left, right).
  std::array<registration::ShapeEstimate, 2> shape{};
  std::array<double, 2> truth_cap_residual_mm{};
  /// The cube's lift [mm] (CubeStatus::lift); in a scene without a cube, the height of the object
  /// the scripted user reaches for (session::nearest_object) over where it was at the first frame.
  double lift_mm = 0, u_angle_deg = 0, d_angle_deg = 0;
  int turns = 0;  ///< completed quarter turns of the top layer (CubeStatus::top_turns)
  std::array<double, 8> force_n{};
  double servo_rate_hz = 0, servo_jitter_max_us = 0;
};

/// Every scored frame of a run, in order (a run is bounded by its length: the report needs all).
struct TruthTrace {
  std::vector<TruthFrame> frames;
};

class TruthScorer final : public FrameSink {
 public:
  /// `truth_models`: the user's hands as the synthetic camera films them; `params`: the session's
  /// main pipeline (compositor mode, model skin). The model ceiling renders in a headless GL
  /// context of the scorer's own, made in on_start on the thread that runs the scorer (the frame
  /// thread, or AsyncSinks' output thread) and released in on_end there.
  TruthScorer(const vision::Camera& camera, const std::array<hand::HandModel, 2>& truth_models,
              const pipeline::FramePipelineParams& params);
  ~TruthScorer() override;
  void on_start() override;
  /// Throws SpidarError on a frame without ground truth (a real camera).
  void on_frame(const FrameEvent& e) override;
  void on_end(const SessionSummary& s) override;
  /// The output time of the newest frame (the sinks after this one) [ms].
  void set_output_ms(double ms);
  const TruthTrace& trace() const { return trace_; }

 private:
  vision::Camera camera_;
  std::array<hand::HandModel, 2> truth_models_;
  render::HandSkinParams skin_;
  render::CompositeMode mode_;
  std::unique_ptr<render::Context> context_;
  std::unique_ptr<sim::ModelCeiling> ceiling_;
  sim::FrameTruthWorkspace ws_;
  TruthTrace trace_;
  std::int64_t last_camera_index_ = -1;
  /// Without a cube: the reached-for object's shape (its index in the scene's shapes, −1 not yet
  /// found) and its height at the first frame [m].
  std::ptrdiff_t object_shape_ = -1;
  double object_z0_m_ = 0;
};

}  // namespace spidar::session
