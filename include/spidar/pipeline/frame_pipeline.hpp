#pragma once
/// The frame thread's work for one camera frame (the camera-rate side of a session):
///
///   camera frame ─► chroma key (matte, silhouette) ─► bracelets (projected wrists)
///                                  │                       │
///   fingertip sample at the frame's exposure time ─► successive adjustment of both hands
///                                                          │
///   scene snapshot + fitted hands ─► render (colour, depth, hand depth) ─► compositor ─► output
///
/// The same code runs on the simulated rig (synthetic camera) and on a real camera. It keeps the
/// previous frame's hands (warm start, temporal prior, bracelet prediction). Not thread-safe: one
/// pipeline per frame thread, whose GL context must be current.
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/device/servo_types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/shape_estimator.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/render/compositor.hpp"
#include "spidar/render/context.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/camera.hpp"
#include "spidar/vision/chroma_key.hpp"

namespace spidar::pipeline {

struct FramePipelineParams {
  vision::ChromaKeyParams chroma_key;
  vision::BraceletParams bracelet;
  registration::RegistrationParams registration;
  render::CompositorParams compositor;  ///< its mode makes `composite`
  /// Also compose in the other mode (FrameResult::other), for comparison only: nobody sees it
  /// live. The demo leaves it to its output thread (session::AsyncSinks::compose_others), off
  /// the frame's path.
  bool other_composite = true;
  int silhouette_margin_px = 40;        ///< distance-transform margin (inward silhouette only)
  /// Run independent stages side by side on two threads (core/side_task.hpp): the chroma key and
  /// the silhouette evidence built on it on a helper thread beside the bracelets on the calling
  /// thread; then the left hand's fit on the helper beside the right hand's (their frames are
  /// offered to the size estimate after both fits, left first). The results are the same either way
  /// (test FramePipelineTest.SideBySideStagesGiveTheSerialResults); on two cores it shortens the
  /// frame by the shorter of each pair (FrameTimings then overlap: their sum exceeds total_ms).
  bool side_by_side = true;
  /// The distance transform at full (1) or half (2) resolution (vision/silhouette.hpp): half costs
  /// about a quarter and moves a pulled point's target by at most ~2 px.
  int silhouette_downsample = 1;
  int first_frame_rounds = 6;           ///< registration rounds on the first frame (cold start)
  /// A bracelet farther than this share of the image width from where the previous fit predicts
  /// it is ignored for that frame (e.g. 0.06 = 38 px at 640 px); 0 = off (default: tried on the
  /// demo, it keeps a fit that has drifted from ever recovering).
  double bracelet_gate = 0.0;
  /// Restart a warm-started fit from the fingertips when its fingertip cost per fingertip stays
  /// above this (dimensionless: 25 = each fingertip 5 σ from the strings, ~7.5 mm at 1.5 mm).
  double restart_fingertip_cost = 25.0;
  /// Every N-th warm frame of each hand (the two hands on different frames), its fit is also tried
  /// from the wrist's other depth along the band's ray (registration/wrist_depth.hpp) for
  /// other_depth_rounds rounds, and kept when its data terms cost less than other_depth_keep
  /// times the warm fit's: a hand fitted at the wrong one of the two depths the fingertips and the
  /// wrist pixel allow agrees with the strings, so the restart above never fires; 0 = never.
  /// Measured (demo, 2026-11-26, night): the long-narrow user's fit no longer collapses after a
  /// late regrasp (seeds 1–6: IoU 0.838–0.859 against 2 runs of 6 at 0.777–0.809, joints 9.0 →
  /// 7.5 px), the default user alike (0.866, seeds 1–4), registration 1.62 → 2.15 ms per frame
  /// (median of the runs' medians); every 6th frame let one collapse through.
  int other_depth_every = 3;
  int other_depth_rounds = 2;
  double other_depth_keep = 0.7;
  /// Take the other depth only when it wins two tries in a row (other_depth_every frames apart).
  /// A single frame's evidence sometimes favours a depth far off: demo, seeds 1–10, with one try
  /// the right hand's wrist jumped 10–15 cm deep at the start of turn 2 in 3 runs, for 3–15 frames
  /// (joints 22–32 px, IoU 0.76–0.80, until a later try switched back); with two, in none (joints
  /// 4.97–5.38 px against 5.05–5.83). A wrong depth held for good is still left, one try later
  /// (0.1 s at 30 fps).
  bool other_depth_confirm = true;
  /// A fit whose cap misses its string by more than this [m] is tried again from each such digit
  /// re-posed on its own (registration/fingertip_reach.hpp: the straight-finger local minimum),
  /// and the re-fit kept if it explains the evidence better; 0 = never.
  double reach_min_miss_m = 0.001;
  /// How the fitted hands are drawn (their depth decides occlusion; their pixels give the IoU):
  /// a skin (tapered bones, rounded palm: render/hand_skin.hpp) or the model's capsules.
  bool skinned_hands = true;
  /// The model hands' skin: the taper and palm fullness of a typical hand and a forearm (it lends
  /// the real forearm its depth, and it hides the palm where the camera sees the forearm in
  /// front), no bracelet. The simulated user's hand is another mesh altogether
  /// (sim/anatomical_hand.hpp) and also differs in length, width, fingertip caps, joint ranges and
  /// an independent little finger.
  render::HandSkinParams model_skin{
      .taper = 0.12, .palm_fullness = 1.2, .forearm_length_m = 0.10, .bracelet = false};
  /// Estimate each hand's length and width while the session runs (registration/shape_estimator.hpp)
  /// and fit with the estimate, starting from the given models; off: their sizes stay as given.
  bool personalise_shape = false;
  registration::ShapeEstimatorParams shape_estimator;
  /// Fit the fingers within their passive ranges (hand::passive_limits of the given models' joint
  /// ranges), not only the active: a fingertip the strings pull on can be pushed past where its
  /// finger moves by itself, as the simulated user's are (sim::UserHands). Off: the active ranges.
  bool passive_range = true;
  /// Hand rotations to start from on the first frame (rotation vectors, world) [rad].
  std::array<Vec3, 2> initial_r_W_hand{Vec3::Zero(), Vec3::Zero()};
  /// Device finger index of each hand's thumb, index, middle, ring (the config's order).
  std::array<std::array<int, 4>, 2> fingers{{{0, 1, 2, 3}, {4, 5, 6, 7}}};
};

/// Wall-clock cost of each stage [ms].
struct FrameTimings {
  /// distance_ms: the silhouette term's evidence (which hand owns which silhouette pixel, and
  /// the distance transform when the inward direction is on); 0 without the term.
  double key_ms = 0, bracelet_ms = 0, distance_ms = 0, registration_ms = 0, render_ms = 0,
         composite_ms = 0, total_ms = 0;
};

struct FrameResult {
  std::array<hand::HandParams, 2> hands;                ///< fitted (left, right)
  /// The hand models the fit used (their sizes change when the shape is personalised).
  std::array<hand::HandModel, 2> models;
  /// The hands' size estimates after this frame (the given sizes when not personalised).
  std::array<registration::ShapeEstimate, 2> shapes;
  std::array<registration::FitReport, 2> fits;
  int restarts = 0;  ///< hands whose fit was restarted this frame
  int depth_switches = 0;  ///< hands whose fit was kept from the wrist's other depth this frame
  int reaches = 0;   ///< hands whose fit was kept from a digit re-posed to its string this frame
  std::array<vision::BraceletObservation, 2> bracelets;
  /// The forearms' directions the fits used (world, unit, from the wrist toward the elbow): given
  /// (set_forearm_directions), estimated from the bands (RegistrationParams::forearm_from_band), or
  /// in line with the hand.
  std::array<Vec3, 2> toward_elbow_W{Vec3(0.0, -1.0, 0.0), Vec3(0.0, -1.0, 0.0)};
  vision::ChromaKeyResult key;
  render::RenderTargets virt;   ///< the virtual scene with the fitted hands (hidden): colour,
                                ///< depth, hand_depth, hand_id (finger render::kForearmPart on
                                ///< the forearm)
  cv::Mat composite;            ///< in params.compositor.mode
  cv::Mat composite_alpha;      ///< CV_32FC1, share of the real image in `composite`
  cv::Mat other;                ///< the other mode (if other_composite)
  cv::Mat other_alpha;
  FrameTimings timings;
};

/// A deep copy of `from` into `to`: every image copied (into `to`'s buffers when they already have
/// the size and type, so a reused `to` allocates nothing), every other field assigned. A plain
/// assignment of FrameResult would share the images, which the pipeline overwrites next frame.
void copy_frame_result(const FrameResult& from, FrameResult* to);

/// The comparison's pipeline params (the demo's `registration.comparison`): `main`'s with the
/// silhouette term switched the other way, and no size estimate of its own (it fits with the
/// main fit's sizes: FramePipeline::use_model_sizes).
FramePipelineParams comparison_params(const FramePipelineParams& main);

/// The compositor parameters of the mode other than `main`'s (FrameResult::other), the rest as
/// `main`'s.
render::CompositorParams other_compositor_params(const render::CompositorParams& main);

/// Composes `result`'s rendering (result.virt) over the camera image `bgr` with its matte
/// (result.key) in `compositor`'s mode into `image` and `alpha` (the share of the real image):
/// FramePipeline's own composites, and the other mode's made elsewhere (e.g. on an output thread).
/// Error on a result without its rendering or matte, or an image of another size.
Status compose_result(render::Compositor& compositor, const FrameResult& result, const cv::Mat& bgr,
                      cv::Mat* image, cv::Mat* alpha);

class FramePipeline {
 public:
  /// `models`: the registration's hand models (left, right). Error on invalid params.
  static Result<std::unique_ptr<FramePipeline>> create(render::Context& context,
                                                       const vision::Camera& camera,
                                                       const std::array<hand::HandModel, 2>& models,
                                                       const FramePipelineParams& params);
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  /// Processes one frame: `bgr` the camera image (camera's size), `fingertips` the servo sample
  /// at its exposure time, `scene` the virtual world. Error on a bad frame (naming what).
  /// With `registration_only` it stops after fitting the hands (no rendering, no composites).
  /// `matte`: this image's chroma key made by another pipeline with the same chroma-key params
  /// (the comparison fit reuses the main pipeline's instead of keying the frame again); it is
  /// shared, not copied, into out->key. Error if its size is not the frame's.
  Status process(const cv::Mat& bgr, const device::FingertipSample& fingertips,
                 const SceneSnapshot& scene, FrameResult* out, bool registration_only = false,
                 const vision::ChromaKeyResult* matte = nullptr);
  /// The picture of a fit made elsewhere (a process() with registration_only, possibly by another
  /// FramePipeline on another thread): renders `scene` with out->hands posed on out->models
  /// (hidden, for depth) into out->virt and composes out->composite (and out->other) from `bgr`
  /// and out->key. The context this pipeline was created with must be current. Error on a bad
  /// frame or a result without its matte.
  Status picture(const cv::Mat& bgr, const SceneSnapshot& scene, FrameResult* out);
  /// Shows an image (e.g. the composite) in the window of `context` (error when headless).
  Status present(render::Context& context, const cv::Mat& bgr);
  /// Forgets the previous frame (the next one is a cold start) and the hands' size estimates
  /// (the models are again the ones given to create()).
  void reset();
  /// The next frame's fits start from these poses (left, right), as from a previous frame's fits:
  /// a re-initialisation by another tracker, or a study's start at the true pose. Non-finite
  /// parameters are refused (the pipeline is left as it was).
  Status warm_start(const std::array<hand::HandParams, 2>& fits);
  /// True once a frame was processed since creation or reset() (the next fit starts from it).
  bool has_previous() const;
  const FramePipelineParams& params() const;
  /// The models the next frame's fits use (the given sizes, or the estimate reached so far).
  const std::array<hand::HandModel, 2>& models() const;
  /// Fits the next frames with these models' sizes (their joint box widened as `passive_range`
  /// says), for a pipeline that learns no sizes itself (personalise_shape off): the comparison fit
  /// takes the main fit's estimate, so the two methods differ in nothing else.
  void use_model_sizes(const std::array<hand::HandModel, 2>& models);
  /// Where each forearm points (left, right): world, from the wrist toward the elbow, for the next
  /// frames' bracelet term, predicted bracelet and forearm outline, kept until set again; nullopt
  /// (the default) or a non-finite or zero vector: in line with the hand, as the paper assumes.
  /// For a rig that tracks the forearms, and for the registration study's --oracle-forearm (the
  /// simulated user's true forearms: how much an estimate of their direction would be worth).
  void set_forearm_directions(const std::array<std::optional<Vec3>, 2>& toward_elbow_W);

 private:
  struct Impl;
  explicit FramePipeline(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A frame to process before a session's clock starts: the screen without hands, the
/// fingertips where the task begins and the scene as it starts.
struct WarmUpFrame {
  cv::Mat bgr;                     ///< CV_8UC3, the camera's size
  device::FingertipSample fingertips;
  SceneSnapshot scene;
};

/// Processes `frame` (the GL driver compiles its shaders at the first draw, the buffers are
/// allocated) and resets the pipeline, so that the first real frame is not the one that pays for
/// it: once into a scratch result, or once into each of `into` (a session's pooled results, whose
/// images are then allocated and touched before its clock starts). The context the pipeline was
/// created with must be current. Error as process().
Status warm_up(FramePipeline& pipeline, const WarmUpFrame& frame, std::span<FrameResult* const> into = {});

/// The comparison's fit of the frame `main` holds (comparison: a pipeline of comparison_params),
/// with the sizes the main fit used on it (use_model_sizes) and its matte (the same image keyed
/// with the same params), into `out`; its picture too when `picture`, else registration only.
/// The context `comparison` was created with must be current. Error as process().
Status process_comparison(FramePipeline& comparison, const FrameResult& main, const cv::Mat& bgr,
                          const device::FingertipSample& fingertips, const SceneSnapshot& scene,
                          bool picture, FrameResult* out);

}  // namespace spidar::pipeline
