#include "spidar/pipeline/frame_pipeline.hpp"

#include <algorithm>
#include <limits>
#include <chrono>
#include <cmath>
#include <opencv2/core.hpp>

#include "spidar/hand/joint_limits.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/core/side_task.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/registration/fingertip_reach.hpp"
#include "spidar/registration/forearm_from_band.hpp"
#include "spidar/registration/wrist_depth.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/registration/shape_estimator.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/vision/silhouette.hpp"

namespace spidar::pipeline {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// The fit's settings for a start far from the hand (the first frame, a restart from the
/// fingertips): without the digits' axes, whose across-the-bone search assumes the model's digit
/// already lies on the real one (from a cold start it finds a neighbouring finger: demo, seed 1,
/// the left hand's first 0.3 s at 10–13 px against 2.5–4 px without them).
registration::RegistrationParams cold_registration_params(registration::RegistrationParams p) {
  p.digit_axis_sigma_px = 0.0;
  return p;
}

/// A cold-start pose: a relaxed hand with the given rotation, placed so that its fingertips'
/// centroid lies on the measured one.
hand::HandParams cold_start(const hand::HandModel& model, const Vec3& r_W_hand,
                            const registration::HandObservation& obs) {
  hand::HandParams q;
  q.set_wrist(Vec3::Zero(), r_W_hand);
  for (int p = hand::kThumbCmcFlexion; p < hand::kParamCount; ++p) q[p] = 0.3;
  q[hand::kIndexMcpAbduction] = q[hand::kRingMcpAbduction] = q[hand::kLittleMcpAbduction] = 0.0;
  q = hand::clamp_to_limits(q, model.limits);
  const hand::HandPoints pts = hand::forward_kinematics(model, q);
  Vec3 model_mean = Vec3::Zero(), measured_mean = Vec3::Zero();
  int n = 0;
  for (int f = 0; f < hand::kFingertipCount; ++f) {
    if (!obs.fingertip_valid[f]) continue;
    model_mean += pts.p_W_fingertip[f];
    measured_mean += obs.p_W_fingertip[f];
    ++n;
  }
  if (n > 0) q.set_wrist((measured_mean - model_mean) / n, r_W_hand);
  return q;
}

/// The camera frame a pipeline can take: CV_8UC3 of the camera's size; else an error saying so.
Status check_frame(const cv::Mat& bgr, const vision::Camera& camera) {
  if (!bgr.empty() && bgr.type() == CV_8UC3 && bgr.cols == camera.width() && bgr.rows == camera.height())
    return Ok{};
  return Error{"frame pipeline: expected a CV_8UC3 frame of " + std::to_string(camera.width()) + "x" +
               std::to_string(camera.height()) + " px, got " + std::to_string(bgr.cols) + "x" +
               std::to_string(bgr.rows)};
}

/// The model a frame's fit uses: `model` with its joint box widened by the passive range
/// (FramePipelineParams::passive_range). The size estimator keeps the active ranges: its keyframe
/// refits then explain the fingertips' spread by the hand's width rather than by fingers pushed
/// apart (demo seeds 1–10: width 2.9–4.5 % off with the passive range there, 1.0–2.1 % without).
hand::HandModel fit_model(hand::HandModel model, const FramePipelineParams& p) {
  if (p.passive_range) model.limits = hand::passive_limits(model.limits);
  return model;
}

/// The fastest of a hand's measured fingertips between two samples `dt_s` apart [m/s]; infinity
/// when none is measured in both or dt_s is not positive (an unknown speed passes no gate).
double fastest_fingertip_m_s(const std::array<Vec3, hand::kFingertipCount>& before,
                             const registration::HandObservation& now, double dt_s) {
  double fastest = -1.0;
  if (dt_s > 0)
    for (int f = 0; f < hand::kFingertipCount; ++f)
      if (now.fingertip_valid[f] && before[f].allFinite())
        fastest = std::max(fastest, (now.p_W_fingertip[f] - before[f]).norm() / dt_s);
  return fastest < 0 ? std::numeric_limits<double>::infinity() : fastest;
}

/// The fit's fingertip cost per measured fingertip (dimensionless: 1 = each σ from the strings);
/// 0 when no fingertip is measured.
double fingertip_cost_per_tip(const registration::FitReport& report, const registration::HandObservation& obs) {
  int valid = 0;
  for (bool v : obs.fingertip_valid) valid += v ? 1 : 0;
  return valid > 0 ? report.terms.fingertip / valid : 0.0;
}

}  // namespace

struct FramePipeline::Impl {
  FramePipelineParams params;
  vision::Camera camera;
  std::array<hand::HandModel, 2> models;
  std::unique_ptr<render::Renderer> renderer;
  vision::ChromaKeyer keyer;
  vision::BraceletWorkspace bracelet_ws;
  vision::SilhouetteDistance distance;
  registration::SuccessiveAdjustment solver;
  /// The same without the digits' axes, for fits from a cold start (see cold_registration_params).
  registration::SuccessiveAdjustment cold_solver;
  render::Compositor main, other;
  SceneSnapshot scene;  ///< the world plus the fitted hands (reused)
  /// The world's meshes followed by the hand skins' (rebuilt when the world's list changes).
  const void* world_meshes = nullptr;
  std::shared_ptr<std::vector<MeshData>> meshes;
  std::array<render::HandSkin, 2> skins;
  std::array<hand::HandParams, 2> previous;
  bool have_previous = false;
  std::uint64_t warm_frames = 0;  ///< frames fitted from a previous one since the last cold start
  /// Per hand: the wrist's other depth explained the evidence better at its last try, not yet
  /// taken (FramePipelineParams::other_depth_confirm).
  std::array<bool, 2> other_depth_won{false, false};
  /// The silhouette term's coverage direction: both hands' outlines at the previous fits and the
  /// silhouette pixels each owns (registration/coverage.hpp).
  std::array<registration::ProjectedHand, 2> outlines;
  std::array<std::vector<registration::OwnedPixel>, 2> owned;
  /// Online size estimates (personalise_shape) from the models given at creation (start), and
  /// the sizes the skins were last built with.
  std::array<hand::HandModel, 2> start;
  /// One estimator for both hands (ShapeEstimatorParams::shared_hands), or one per hand.
  std::vector<registration::ShapeEstimator> shape;
  std::array<hand::HandDimensions, 2> skin_dims;
  /// The helper thread of FramePipelineParams::side_by_side (made at the first frame, by the
  /// thread that processes it).
  core::SideTask side;
  /// This frame's predicted bracelets (find_bracelets): where the previous fits put them [px].
  std::array<Vec2, 2> predicted_wrist_px{Vec2::Zero(), Vec2::Zero()};
  /// Where each forearm points, world (set_forearm_directions), and the same in each hand's frame
  /// at the previous fit (HandObservation::forearm_H), set at the start of each frame.
  std::array<std::optional<Vec3>, 2> toward_elbow_W;
  std::array<Vec3, 2> forearm_H{Vec3(0.0, -1.0, 0.0), Vec3(0.0, -1.0, 0.0)};
  /// The forearms' directions estimated from their bands (registration/forearm_from_band.hpp),
  /// world, from the last frame that showed them.
  std::array<std::optional<Vec3>, 2> estimated_toward_elbow_W;
  /// Each hand's fingertips from the strings at the previous frame (world [m]; NaN = not measured)
  /// and that frame's sample time [ns]: how fast the hand moves (ShapeEstimatorParams::max_keyframe_speed_m_s).
  std::array<std::array<Vec3, hand::kFingertipCount>, 2> previous_tips_W{};
  std::int64_t previous_tips_t_ns = 0;
  bool have_previous_tips = false;

  Status key_and_evidence(const cv::Mat& bgr, const vision::ChromaKeyResult* matte, FrameResult* out);
  Status find_bracelets(const cv::Mat& bgr, FrameResult* out);

  Impl(const FramePipelineParams& p, vision::ChromaKeyer k,
       const std::array<hand::HandModel, 2>& given)
      : params(p),
        models{fit_model(given[0], p), fit_model(given[1], p)},
        keyer(std::move(k)),
        solver(p.registration),
        cold_solver(cold_registration_params(p.registration)),
        main(p.compositor),
        start(given) {
    make_estimators();
    other.set_params(other_compositor_params(p.compositor));
  }

  void make_estimators() {
    shape.clear();
    if (params.shape_estimator.shared_hands) {
      shape.emplace_back(start, params.shape_estimator);
    } else {
      for (int h = 0; h < 2; ++h) shape.emplace_back(start[h], params.shape_estimator);
    }
  }
  /// The estimator of hand h, and h's index in it.
  registration::ShapeEstimator& estimator_of(int h) { return shape[shape.size() == 1 ? 0 : static_cast<std::size_t>(h)]; }
  int index_in_estimator(int h) const { return shape.size() == 1 ? h : 0; }
  /// After estimator `e` changed its sizes: the fits of the hands it holds take its models.
  void take_sizes(const registration::ShapeEstimator& e) {
    for (int h = 0; h < 2; ++h)
      if (&estimator_of(h) == &e) models[h] = fit_model(e.model(index_in_estimator(h)), params);
  }
};

Result<std::unique_ptr<FramePipeline>> FramePipeline::create(
    render::Context& context, const vision::Camera& camera,
    const std::array<hand::HandModel, 2>& models, const FramePipelineParams& params) {
  if (models[0].side != hand::Side::kLeft || models[1].side != hand::Side::kRight)
    return Error{"frame pipeline: hand models must be {left, right}"};
  if (auto s = registration::validate(params.registration); !s) return s.error();
  if (auto s = vision::validate(params.bracelet); !s) return s.error();
  if (auto s = render::validate(params.compositor); !s) return s.error();
  if (params.skinned_hands) {
    if (auto s = render::validate(params.model_skin); !s) return Error{"frame pipeline: model_skin: " + s.error().message};
  }
  if (params.silhouette_downsample != 1 && params.silhouette_downsample != 2)
    return Error{"frame pipeline: silhouette_downsample: expected 1 or 2, got " +
                 std::to_string(params.silhouette_downsample)};
  for (const auto& hand_fingers : params.fingers) {
    for (int f : hand_fingers) {
      if (f < 0 || f >= device::kMaxFingers)
        return Error{"frame pipeline: finger index " + std::to_string(f) + " outside 0.." +
                     std::to_string(device::kMaxFingers - 1)};
    }
  }
  auto keyer = vision::ChromaKeyer::create(params.chroma_key);
  if (!keyer) return keyer.error();
  auto impl = std::make_unique<Impl>(params, std::move(keyer).value(), models);
  impl->camera = camera;
  auto renderer = render::Renderer::create(context, camera.width(), camera.height());
  if (!renderer) return renderer.error();
  impl->renderer = std::move(renderer).value();
  return std::unique_ptr<FramePipeline>(new FramePipeline(std::move(impl)));
}

FramePipeline::FramePipeline(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FramePipeline::~FramePipeline() = default;
void FramePipeline::reset() {
  Impl& s = *impl_;
  s.have_previous = false;
  s.warm_frames = 0;
  s.other_depth_won = {false, false};
  // A cold start forgets the sizes learnt too: a session's warm-up frame (a blank screen) must
  // not stay among the estimator's keyframes, or a replay, which has no warm-up, would not
  // reach the live run's sizes.
  for (int h = 0; h < 2; ++h) s.models[h] = fit_model(s.start[h], s.params);
  s.make_estimators();
  s.estimated_toward_elbow_W = {};
  s.have_previous_tips = false;
}
Status FramePipeline::warm_start(const std::array<hand::HandParams, 2>& fits) {
  for (int h = 0; h < 2; ++h)
    if (!fits[h].q.allFinite())
      return Error{std::string("frame pipeline: warm_start: the ") + (h == 0 ? "left" : "right") +
                   " hand's parameters are not finite"};
  impl_->previous = fits;
  impl_->have_previous = true;
  impl_->other_depth_won = {false, false};
  return Ok{};
}
bool FramePipeline::has_previous() const { return impl_->have_previous; }
Status FramePipeline::present(render::Context& context, const cv::Mat& bgr) {
  return impl_->renderer->present(context, bgr);
}
const FramePipelineParams& FramePipeline::params() const { return impl_->params; }
const std::array<hand::HandModel, 2>& FramePipeline::models() const { return impl_->models; }
void FramePipeline::set_forearm_directions(const std::array<std::optional<Vec3>, 2>& toward_elbow_W) {
  impl_->toward_elbow_W = toward_elbow_W;
}

void FramePipeline::use_model_sizes(const std::array<hand::HandModel, 2>& models) {
  Impl& s = *impl_;
  for (int h = 0; h < 2; ++h) {
    const hand::HandDimensions& want = models[h].shape.dimensions;
    const hand::HandDimensions& have = s.models[h].shape.dimensions;
    if (want.length == have.length && want.width == have.width && want.thickness == have.thickness)
      continue;
    auto m = registration::resized(s.start[h], want.length, want.width, want.thickness);
    if (m) s.models[h] = fit_model(std::move(m).value(), s.params);
  }
}

/// The chroma key (or the matte given for this image) and, for the silhouette term, its
/// distance transform and which hand owns which silhouette pixel at the previous fits. Writes
/// out->key, out->timings.{key,distance}_ms, s.distance, s.outlines and s.owned only.
Status FramePipeline::Impl::key_and_evidence(const cv::Mat& bgr, const vision::ChromaKeyResult* matte,
                                             FrameResult* out) {
  Impl& s = *this;
  const FramePipelineParams& p = s.params;
  FrameTimings& tm = out->timings;
  auto t0 = Clock::now();
  if (matte != nullptr) {
    if (matte->alpha.size() != bgr.size() || matte->silhouette.size() != bgr.size())
      return Error{"frame pipeline: the matte given is not the frame's size"};
    out->key = *matte;  // shares its images
  } else if (auto st = s.keyer.apply(bgr, &out->key); !st) {
    return st;
  }
  tm.key_ms = ms_since(t0);

  t0 = Clock::now();
  if (p.registration.silhouette_term && p.registration.silhouette_inward) {
    vision::SilhouetteDistanceOptions o;
    o.max_distance_px = p.silhouette_margin_px;
    o.downsample = p.silhouette_downsample;
    if (auto st = vision::silhouette_distance(out->key.silhouette, &s.distance, o); !st) return st;
  }
  if (p.registration.silhouette_term) {
    if (s.have_previous) {
      for (int h = 0; h < 2; ++h) {
        const double forearm_radius =
            registration::bracelet_radius_m(p.registration, s.models[h].shape.dimensions.width);
        registration::project_hand(s.models[h], s.previous[h], s.camera, forearm_radius, &s.outlines[h],
                                   s.forearm_H[h]);
      }
      registration::coverage_evidence(out->key.silhouette, {&s.outlines[0], &s.outlines[1]},
                                      p.registration, &s.owned);
    } else {
      for (auto& pixels : s.owned) pixels.clear();
    }
  }
  tm.distance_ms = ms_since(t0);
  return Ok{};
}

/// Both bracelets, each searched for where the previous fit puts it. Writes out->bracelets,
/// out->timings.bracelet_ms, s.bracelet_ws and s.predicted_wrist_px only.
Status FramePipeline::Impl::find_bracelets(const cv::Mat& bgr, FrameResult* out) {
  Impl& s = *this;
  const FramePipelineParams& p = s.params;
  const auto t0 = Clock::now();
  // Predicted bracelets: where the previous fit puts each hand's bracelet (registration's
  // bracelet_offset_m from the wrist toward the elbow).
  vision::BraceletPrediction prediction;
  std::array<Vec2, 2>& predicted = s.predicted_wrist_px;
  predicted.fill(Vec2::Zero());
  if (s.have_previous) {
    for (int h = 0; h < 2; ++h) {
      const Pose X_WH = hand::hand_pose(s.previous[h]);
      const Vec3 p_WB = X_WH * Vec3(p.registration.bracelet_offset_m * s.forearm_H[h]);
      predicted[h] = s.camera.project(registration::bracelet_visible_point(
          X_WH, s.models[h].shape.dimensions.width, s.camera.X_WC().p, p.registration, nullptr, s.forearm_H[h]));
      prediction.wrist_px[h] = predicted[h];
      // The band's expected length: its projected diameter there.
      const double depth = (s.camera.X_CW() * p_WB).z();
      if (depth > 1e-3) {
        const double radius = registration::bracelet_radius_m(p.registration, s.models[h].shape.dimensions.width);
        prediction.length_px[h] = 2.0 * radius * s.camera.intrinsics().fx / depth;
      }
      // The band's long axis in the image: across the forearm and the line of sight.
      // Only where the camera sees the forearm from the side (its axis more than 58° off the line
      // of sight, sin > 0.85): nearer end-on the band is a ring whose visible arc's long axis
      // need not lie across the forearm, and a predicted axis made the detector refuse the
      // right band there (registration_study: the right bracelet lost for 14 frames at 6.1–6.6 s,
      // its wrist drifting 3 cm).
      const Vec3 sight = p_WB - s.camera.X_WC().p;
      const Vec3 across = (X_WH.R * Vec3(-s.forearm_H[h])).cross(sight);
      if (across.norm() > 0.85 * sight.norm()) {
        const Vec2 a = s.camera.project(p_WB + 0.01 * across.normalized()) - predicted[h];
        if (a.norm() > 1e-6) prediction.axis_px[h] = a.normalized();
      }
    }
  }
  auto found = vision::detect_bracelets(bgr, p.bracelet, s.have_previous ? &prediction : nullptr,
                                        &s.bracelet_ws);
  if (!found) return found.error();
  out->bracelets = *found;
  out->timings.bracelet_ms = ms_since(t0);
  return Ok{};
}

Status FramePipeline::process(const cv::Mat& bgr, const device::FingertipSample& tips,
                              const SceneSnapshot& world, FrameResult* out,
                              bool registration_only, const vision::ChromaKeyResult* matte) {
  if (out == nullptr) return Error{"frame pipeline: no output given"};
  Impl& s = *impl_;
  const FramePipelineParams& p = s.params;
  if (auto st = check_frame(bgr, s.camera); !st) return st;
  const auto t_start = Clock::now();
  // Each forearm's direction in its hand's frame at the previous fit: for the predicted bracelet,
  // the forearm outline that decides the silhouette's owners, and the bracelet term.
  for (int h = 0; h < 2; ++h) {
    s.forearm_H[h] = Vec3(0.0, -1.0, 0.0);
    const auto& given = s.toward_elbow_W[static_cast<std::size_t>(h)];
    const auto& d = given ? given : s.estimated_toward_elbow_W[static_cast<std::size_t>(h)];
    if (s.have_previous && d && d->allFinite() && d->norm() > 0.5)
      s.forearm_H[h] = hand::hand_pose(s.previous[h]).R.toRotationMatrix().transpose() * d->normalized();
  }
  FrameTimings& tm = out->timings;

  // The image's two independent stages side by side (FramePipelineParams::side_by_side): the
  // matte and the silhouette evidence built on it on the helper thread, the bracelets on this one.
  // Each writes only its own outputs; both read the previous fits, which neither changes.
  Status key_status = Ok{}, bracelet_status = Ok{};
  auto matte_and_evidence = [&] { key_status = s.key_and_evidence(bgr, matte, out); };
  auto bracelets = [&] { bracelet_status = s.find_bracelets(bgr, out); };
  core::run_side_by_side(p.side_by_side ? &s.side : nullptr, matte_and_evidence, bracelets);
  if (!key_status) return key_status;
  if (!bracelet_status) return bracelet_status;
  registration::ImageEvidence image;
  image.camera = &s.camera;
  image.alpha = out->key.alpha;
  if (p.registration.silhouette_term && p.registration.silhouette_inward) image.distance = &s.distance;

  // Successive adjustment of both hands.
  auto t0 = Clock::now();
  // A size re-estimate running on its own thread takes effect here, a fixed number of frames after
  // it started (ShapeEstimatorParams::apply_after_frames), so the fits stay reproducible.
  if (p.personalise_shape)
    for (registration::ShapeEstimator& e : s.shape)
      if (e.poll()) s.take_sizes(e);
  std::array<std::array<Vec3, hand::kFingertipCount>, 2> next_tips_W{};
  // Each hand's fit writes only that hand's outputs and state (its model, estimator, counters):
  // the two can run side by side.
  struct HandCounts {
    int restarts = 0, depth_switches = 0, reaches = 0;
  };
  std::array<HandCounts, 2> counts{};
  // What each fit offers the size estimate, taken after both fits (an estimator shared by both
  // hands must not be fed from two threads; ShapeEstimatorParams::shared_hands).
  struct SizeOffer {
    bool offered = false;
    registration::HandObservation obs;
    registration::ImageEvidence image;
  };
  std::array<SizeOffer, 2> offers{};
  auto fit_hand = [&](int h) {
    registration::HandObservation obs;
    obs.forearm_H = s.forearm_H[h];
    // The forearm's bend from this frame's band, from the previous fit's pose (forearm_from_band.hpp);
    // directions given by set_forearm_directions take precedence.
    if (registration::forearms_from_bands(p.registration) && s.have_previous &&
        !s.toward_elbow_W[static_cast<std::size_t>(h)] && out->bracelets[h].found) {
      const vision::BraceletObservation& b = out->bracelets[h];
      const registration::BandObservation band{b.end_a_px, b.end_b_px, b.length_px, b.thickness_px, b.fill, b.bulge_px};
      const Pose X_WH = hand::hand_pose(s.previous[h]);
      const auto& last = s.estimated_toward_elbow_W[static_cast<std::size_t>(h)];
      const Vec3 last_H = last ? Vec3(X_WH.R.conjugate() * *last) : Vec3(0.0, -1.0, 0.0);
      if (const auto est = registration::forearm_from_band(X_WH, s.models[h].shape.dimensions.width, s.camera,
                                                           p.registration, band, &last_H)) {
        obs.forearm_H = *est;
        s.estimated_toward_elbow_W[static_cast<std::size_t>(h)] = X_WH.R * *est;
      }
    }
    for (int f = 0; f < hand::kFingertipCount; ++f) {
      const int d = p.fingers[h][f];
      const Vec3 x = device::fingertip_position(tips, d);
      obs.p_W_fingertip[f] = x;
      obs.fingertip_valid[f] = d < tips.finger_count && x.allFinite();
    }
    // A bracelet far from where the previous fit predicts it is more likely the other hand's or a
    // broken detection than a jump of the hand: it is not used (gate scaled to the image width).
    const double gate = p.bracelet_gate * s.camera.width();
    if (out->bracelets[h].found &&
        (gate <= 0 || !s.have_previous || (out->bracelets[h].wrist_px - s.predicted_wrist_px[h]).norm() <= gate)) {
      obs.wrist_px = out->bracelets[h].wrist_px;
      obs.wrist_confidence = out->bracelets[h].confidence;
      // A whole band's length says how far along its ray the wrist is (residuals.hpp, the band
      // term): used where both its ends are inside the image, it is not ragged, and it is within
      // bracelet_length_gate of the length the band term's model predicts at the previous fit.
      const vision::BraceletObservation& band = out->bracelets[h];
      const auto inside = [&](const Vec2& e) {
        return e.x() >= 2.0 && e.y() >= 2.0 && e.x() <= s.camera.width() - 3.0 && e.y() <= s.camera.height() - 3.0;
      };
      const bool solid = band.fill >= p.registration.bracelet_length_min_fill && inside(band.end_a_px) &&
                         inside(band.end_b_px);
      const double gate_share = p.registration.bracelet_length_gate;
      auto within_gate = [&](double measured, double expected) {
        return expected <= 0 || std::abs(measured / expected - 1.0) <= gate_share;
      };
      if (p.registration.bracelet_length_sigma > 0 && solid) {
        const double expected =
            s.have_previous ? registration::bracelet_length_px(hand::hand_pose(s.previous[h]),
                                                               s.models[h].shape.dimensions.width, s.camera,
                                                               p.registration)
                            : 0.0;
        if (within_gate(band.length_px, expected)) obs.wrist_length_px = band.length_px;
      }
      // Its thickness across its long axis, likewise (registration_params.hpp).
      const Vec2 axis = band.end_b_px - band.end_a_px;
      if (p.registration.bracelet_thickness_sigma > 0 && solid && axis.norm() > 1e-6) {
        const Vec2 unit = axis.normalized();
        const double expected =
            s.have_previous ? registration::bracelet_band_thickness(hand::hand_pose(s.previous[h]),
                                                                    s.models[h].shape.dimensions.width, s.camera,
                                                                    p.registration, Vec2(-unit.y(), unit.x()))
                            : 0.0;
        if (within_gate(band.thickness_px, expected)) {
          obs.wrist_thickness_px = band.thickness_px;
          obs.wrist_axis_px = unit;
        }
      }
    }
    const bool cold = !s.have_previous;
    registration::ImageEvidence hand_image = image;
    if (p.registration.silhouette_term && s.have_previous) hand_image.coverage = &s.owned[h];
    auto fit_from = [&](hand::HandParams q, const hand::HandParams* prior, int rounds,
                        registration::FitReport* report, bool from_cold = false) {
      const registration::SuccessiveAdjustment& solver = from_cold ? s.cold_solver : s.solver;
      for (int r = 0; r < rounds; ++r) {
        const registration::FitReport rr = solver.fit(s.models[h], obs, hand_image, prior, &q);
        if (r == 0) report->cost_initial = rr.cost_initial;
        report->iterations += rr.iterations;
        report->cost_final = rr.cost_final;
        report->terms = rr.terms;
        report->converged = rr.converged;
      }
      return q;
    };
    registration::FitReport report;
    hand::HandParams q;
    if (cold) {
      q = fit_from(cold_start(s.models[h], p.initial_r_W_hand[h], obs), nullptr,
                   p.first_frame_rounds, &report, true);
    } else {
      const hand::HandParams prior = s.previous[h];
      q = fit_from(prior, &prior, 1, &report);
      // A fit that cannot bring the fingertips to the strings has lost the hand (a wrong
      // bracelet, a local minimum): start again from the fingertips, keeping the rotation, and
      // keep whichever fit is cheaper.
      if (fingertip_cost_per_tip(report, obs) > p.restart_fingertip_cost) {
        registration::FitReport again;
        const hand::HandParams q2 =
            fit_from(cold_start(s.models[h], prior.r_W_hand(), obs), nullptr, p.first_frame_rounds, &again, true);
        again.iterations += report.iterations;
        if (again.cost_final < report.cost_final) {
          q = q2;
          report = again;
        } else {
          report.iterations = again.iterations;
        }
        ++counts[h].restarts;
      }
      // The wrist's other depth along its band's ray (registration/wrist_depth.hpp): fitted from
      // there every other_depth_every-th warm frame, kept when it explains the evidence clearly
      // better (the prior left out of the comparison: it holds the basin the warm fit is in), at
      // two tries in a row.
      const auto every = static_cast<std::uint64_t>(std::max(p.other_depth_every, 0));
      if (every > 0 && s.warm_frames % every == static_cast<std::uint64_t>(h) % every) {
        bool pending = false;  // won this try, not taken yet
        if (auto start = registration::other_wrist_depth(s.models[h], q, obs, s.camera)) {
          registration::FitReport other;
          const hand::HandParams q2 = fit_from(*start, nullptr, p.other_depth_rounds, &other);
          other.iterations += report.iterations;
          const bool won = q2.q.allFinite() && other.terms.evidence() < p.other_depth_keep * report.terms.evidence();
          // Taken at its second win in a row (other_depth_confirm): one frame's evidence can
          // favour a wrong depth by far, and the fit then sits there until the next try.
          const bool take = won && (!p.other_depth_confirm || s.other_depth_won[h]);
          pending = won && !take;
          if (take) {
            q = q2;
            report = other;
            ++counts[h].depth_switches;
          } else {
            report.iterations = other.iterations;
          }
        }
        s.other_depth_won[h] = pending;
      }
    }
    // A digit stalled short of its string: try again from it re-posed on its own (its prior mean
    // moved along, or the prior would hold the old basin), and keep the re-fit if it explains the
    // evidence better; the prior is left out of that comparison for the same reason.
    if (p.reach_min_miss_m > 0 &&
        registration::refit_reaching(s.solver, s.models[h], obs, hand_image, cold ? nullptr : &s.previous[h],
                                     {.min_miss_m = p.reach_min_miss_m}, &q, &report))
      ++counts[h].reaches;
    out->hands[h] = q;
    out->fits[h] = report;
    out->toward_elbow_W[h] = hand::hand_pose(s.have_previous ? s.previous[h] : q).R * obs.forearm_H;
    out->models[h] = s.models[h];
    // Personalisation: this frame's evidence on the hand's sizes; the next fit uses the estimate.
    // Only a fit that agrees with the strings is evidence on the sizes: a broken one (a lost
    // bracelet, a local minimum) would pull them toward whatever explains it.
    // (A frame without all four fingertips makes no keyframe anyway: ShapeEstimator::add_frame.)
    // A fast hand's frame mixes times (ShapeEstimatorParams::max_keyframe_speed_m_s).
    const double speed_gate = p.shape_estimator.max_keyframe_speed_m_s;
    const bool still = speed_gate <= 0 ||
                       (s.have_previous_tips &&
                        fastest_fingertip_m_s(s.previous_tips_W[h], obs, 1e-9 * double(tips.t_ns - s.previous_tips_t_ns)) <=
                            speed_gate);
    for (int f = 0; f < hand::kFingertipCount; ++f)
      next_tips_W[h][f] = obs.fingertip_valid[f] ? obs.p_W_fingertip[f] : Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    if (p.personalise_shape && still && fingertip_cost_per_tip(report, obs) <= p.shape_estimator.max_fingertip_cost)
      offers[h] = SizeOffer{true, obs, hand_image};
  };
  core::run_side_by_side(p.side_by_side ? &s.side : nullptr, [&] { fit_hand(0); }, [&] { fit_hand(1); });
  // The fits' evidence on the sizes, left hand first; the next frame's fits use the estimate.
  for (int h = 0; h < 2; ++h) {
    if (offers[h].offered) {
      registration::ShapeEstimator& e = s.estimator_of(h);
      if (e.add_frame(s.index_in_estimator(h), out->hands[h], offers[h].obs, offers[h].image, p.registration))
        s.take_sizes(e);
    }
  }
  for (int h = 0; h < 2; ++h) out->shapes[h] = s.estimator_of(h).estimate(s.index_in_estimator(h));
  out->restarts = counts[0].restarts + counts[1].restarts;
  out->depth_switches = counts[0].depth_switches + counts[1].depth_switches;
  out->reaches = counts[0].reaches + counts[1].reaches;
  s.previous = out->hands;
  s.previous_tips_W = next_tips_W;
  s.previous_tips_t_ns = tips.t_ns;
  s.have_previous_tips = true;
  if (s.have_previous) ++s.warm_frames;
  s.have_previous = true;
  tm.registration_ms = ms_since(t0);
  if (registration_only) {
    tm.render_ms = tm.composite_ms = 0;
    tm.total_ms = ms_since(t_start);
    return Ok{};
  }
  if (auto st = picture(bgr, world, out); !st) return st;
  tm.total_ms = ms_since(t_start);
  return Ok{};
}

Status process_comparison(FramePipeline& comparison, const FrameResult& main, const cv::Mat& bgr,
                          const device::FingertipSample& fingertips, const SceneSnapshot& scene,
                          bool picture, FrameResult* out) {
  comparison.use_model_sizes(main.models);
  const bool same_key = main.key.alpha.size() == bgr.size();
  return comparison.process(bgr, fingertips, scene, out, !picture, same_key ? &main.key : nullptr);
}

FramePipelineParams comparison_params(const FramePipelineParams& main) {
  FramePipelineParams alt = main;
  alt.registration.silhouette_term = !alt.registration.silhouette_term;
  alt.personalise_shape = false;
  return alt;
}

render::CompositorParams other_compositor_params(const render::CompositorParams& main) {
  render::CompositorParams o = main;
  o.mode = main.mode == render::CompositeMode::kDepth ? render::CompositeMode::kPaper
                                                      : render::CompositeMode::kDepth;
  return o;
}

Status compose_result(render::Compositor& compositor, const FrameResult& result, const cv::Mat& bgr,
                      cv::Mat* image, cv::Mat* alpha) {
  if (result.key.alpha.size() != bgr.size())
    return Error{"composite: the result has no matte of the image's size (FrameResult::key)"};
  render::CompositeInputs in;
  in.virt = &result.virt;
  const bool depth = compositor.params().mode == render::CompositeMode::kDepth;
  in.real_bgr = depth && !result.key.foreground.empty() ? result.key.foreground : bgr;
  in.real_alpha = result.key.alpha;
  return compositor.compose(in, image, alpha);
}

Status FramePipeline::picture(const cv::Mat& bgr, const SceneSnapshot& world, FrameResult* out) {
  if (out == nullptr) return Error{"frame pipeline: no output given"};
  Impl& s = *impl_;
  const FramePipelineParams& p = s.params;
  if (auto st = check_frame(bgr, s.camera); !st) return st;
  if (out->key.alpha.size() != bgr.size())
    return Error{"frame pipeline: picture needs the frame's matte (FrameResult::key) from its fit"};
  FrameTimings& tm = out->timings;
  // The hand models the fit used (the sizes a personalising fit had reached).
  const std::array<hand::HandModel, 2>& models = out->models;

  // The virtual scene with the fitted hands (hidden: they only give depth).
  auto t0 = Clock::now();
  s.scene.t_s = world.t_s;
  s.scene.shapes = world.shapes;
  if (p.skinned_hands) {
    // Rebuild the skins when the world's meshes change or a hand's estimated size moved by more
    // than half a millimetre since they were built.
    bool resized = false;
    for (int h = 0; h < 2; ++h) {
      const auto& d = models[h].shape.dimensions;
      resized = resized || std::abs(d.length - s.skin_dims[h].length) > 5e-4 ||
                std::abs(d.width - s.skin_dims[h].width) > 5e-4;
    }
    if (!s.meshes || s.world_meshes != world.meshes.get() || resized) {
      for (int h = 0; h < 2; ++h) s.skin_dims[h] = models[h].shape.dimensions;
      auto meshes = std::make_shared<std::vector<MeshData>>();
      if (world.meshes) *meshes = *world.meshes;
      for (int h = 0; h < 2; ++h) s.skins[h] = render::build_hand_skin(models[h], p.model_skin, meshes.get());
      s.meshes = std::move(meshes);
      s.world_meshes = world.meshes.get();
    }
    s.scene.meshes = s.meshes;
    for (int h = 0; h < 2; ++h)
      render::pose_hand_skin(models[h], s.skins[h], out->hands[h], p.model_skin, &s.scene);
  } else {
    s.scene.meshes = world.meshes;
    for (int h = 0; h < 2; ++h)
      render::append_hand_shapes(hand::hand_render_shapes(models[h], out->hands[h]), &s.scene);
  }
  render::RenderParams rp;
  rp.hands = render::HandDrawMode::kHidden;
  if (auto st = s.renderer->render(s.scene, s.camera, rp); !st) return st;
  if (auto st = s.renderer->read(&out->virt, render::kAllTargets); !st) return st;
  tm.render_ms = ms_since(t0);

  // Compositing.
  t0 = Clock::now();
  if (auto st = compose_result(s.main, *out, bgr, &out->composite, &out->composite_alpha); !st) return st;
  if (p.other_composite) {
    if (auto st = compose_result(s.other, *out, bgr, &out->other, &out->other_alpha); !st) return st;
  } else {
    out->other.release();  // a result reused from a pool must not show an older frame's
    out->other_alpha.release();
  }
  tm.composite_ms = ms_since(t0);
  return Ok{};
}

Status warm_up(FramePipeline& pipeline, const WarmUpFrame& frame, std::span<FrameResult* const> into) {
  FrameResult scratch;
  std::vector<FrameResult*> outs(into.begin(), into.end());
  if (outs.empty()) outs.push_back(&scratch);
  for (FrameResult* out : outs) {
    if (out == nullptr) return Error{"warm-up frame: no result given"};
    if (auto st = pipeline.process(frame.bgr, frame.fingertips, frame.scene, out); !st)
      return Error{"warm-up frame: " + st.error().message};
  }
  pipeline.reset();
  return Ok{};
}

}  // namespace spidar::pipeline
