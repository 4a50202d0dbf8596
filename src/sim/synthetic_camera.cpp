#include "spidar/sim/synthetic_camera.hpp"

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/render/hand_skin.hpp"  // part ids
#include "spidar/render/renderer.hpp"
#include "spidar/sim/anatomical_hand.hpp"
#include "spidar/vision/lens_undistortion.hpp"

namespace spidar::sim {

Status validate(const SyntheticCameraParams& p) {
  auto bad = [](const std::string& what) { return Status(Error{"synthetic camera: " + what}); };
  for (const auto* c : {&p.screen_rgb, &p.skin_rgb, &p.bracelet_rgb, &p.nail_rgb})
    for (float v : *c)
      if (!(v >= 0.f && v <= 1.f)) return bad("colours must be in [0, 1]");
  if (!(p.bracelet_width_m > 0 && p.bracelet_width_m < 0.1))
    return bad("bracelet_width_m must be in (0, 0.1) m, got " + std::to_string(p.bracelet_width_m));
  if (!(p.bracelet_offset_m >= 0 && p.bracelet_offset_m < 0.1))
    return bad("bracelet_offset_m must be in [0, 0.1) m");
  if (!(p.max_wrist_bend_rad > 0 && p.max_wrist_bend_rad <= 0.5 * std::numbers::pi))
    return bad("max_wrist_bend_rad must be in (0, pi/2], got " + std::to_string(p.max_wrist_bend_rad));
  if (p.elbows_W && !((*p.elbows_W)[0].allFinite() && (*p.elbows_W)[1].allFinite()))
    return bad("elbows_W must be finite");
  if (!(p.forearm_length_m >= 0 && p.forearm_length_m <= 0.5))
    return bad("forearm_length_m must be in [0, 0.5] m");
  if (!(p.ambient >= 0.f && p.ambient <= 1.f)) return bad("ambient must be in [0, 1]");
  if (!p.light_dir_C.allFinite() || p.light_dir_C.norm() < 1e-9) return bad("light_dir_C must be a direction");
  if (!(p.psf_sigma_px >= 0 && p.psf_sigma_px <= 5)) return bad("psf_sigma_px must be in [0, 5]");
  if (!(p.noise_sigma >= 0 && p.noise_sigma <= 64)) return bad("noise_sigma must be in [0, 64]");
  if (p.motion_blur_samples < 1 || p.motion_blur_samples > 32)
    return bad("motion_blur_samples must be in 1..32, got " + std::to_string(p.motion_blur_samples));
  return Ok{};
}

struct SyntheticCamera::Impl {
  vision::Camera camera;  ///< as given (its lens, if any)
  /// With lens distortion: the hands are drawn by the pinhole camera its frames undistort into
  /// (the ground truth stays in that view, where the pipeline works), and the colour image is then
  /// bent through the lens, as a real camera's is.
  std::optional<vision::LensUndistortion> lens;
  vision::Camera drawn;  ///< the camera the renderer draws with (pinhole)
  cv::Mat through_lens;
  SyntheticCameraParams params;

  /// camera, lens and drawn for `c`; nothing changes on error (a lens that cannot be undistorted).
  Status set_camera(const vision::Camera& c) {
    auto l = vision::LensUndistortion::of(c.intrinsics());
    if (!l) return Error{"synthetic camera: " + l.error().message};
    drawn = l.value() ? l.value()->pinhole_camera(c.X_CW()) : c;
    camera = c;
    lens = std::move(l).value();
    return Ok{};
  }
  std::array<AnatomicalHand, 2> hands;
  /// Both hands' parts, left then right: posed in place every frame (MeshData::version).
  std::shared_ptr<std::vector<MeshData>> meshes;
  std::array<std::size_t, 2> first_mesh{};
  std::unique_ptr<render::Renderer> renderer;
  render::RenderParams render_params;
  SceneSnapshot scene;
  render::RenderTargets targets;
  cv::Mat accumulator;
  /// The sensor noise bank as its positive and negative parts (8-bit each, one of the two zero per
  /// sample): adding one and subtracting the other, both saturating, is the saturated sum with
  /// the signed noise, in two SIMD passes instead of a mixed-type one.
  cv::Mat noise_plus, noise_minus;
  /// hand_id → hand_index (0, or hand + 1) and → hand_only (255 for a hand part that is neither
  /// bracelet nor forearm) (render::decode_hand_id).
  cv::Mat lut_index, lut_only;
  cv::RNG rng;

  /// A film_image whose ground truth film_truth has not read yet (it is in the renderer's targets).
  bool truth_pending = false;
  /// Where each forearm pointed in the last build_scene.
  std::array<std::optional<Vec3>, 2> toward_elbow;

  void build_scene(const HandPoses& poses) {
    scene.shapes.clear();
    toward_elbow = {};
    scene.meshes = meshes;
    for (int h = 0; h < 2; ++h) {
      if (!poses[h]) continue;
      const AnatomicalHand& hand = hands[static_cast<std::size_t>(h)];
      const std::size_t first = first_mesh[static_cast<std::size_t>(h)];
      auto& d = toward_elbow[static_cast<std::size_t>(h)];
      if (params.elbows_W) {
        const hand::HandParams& q = *poses[h];
        d = hand::forearm_direction(hand::rotation_from_vector(q.r_W_hand()), q.p_W_wrist(),
                                    (*params.elbows_W)[static_cast<std::size_t>(h)], params.max_wrist_bend_rad);
      }
      pose_anatomical_hand(hand, *poses[h], std::span<MeshData>(*meshes).subspan(first, hand.parts.size()),
                           d ? &*d : nullptr);
      for (std::size_t i = 0; i < hand.parts.size(); ++i) {
        Shape s;  // vertices are in world already: X_WS = identity
        s.type = Shape::Type::kMesh;
        s.mesh = static_cast<int>(first + i);
        s.hand = h;
        s.finger = hand.parts[i].finger;
        const auto& c = hand.parts[i].rgb;
        s.rgba = {c[0], c[1], c[2], 1.f};
        scene.shapes.push_back(s);
      }
    }
  }
};

SyntheticCamera::SyntheticCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SyntheticCamera::~SyntheticCamera() = default;

Result<std::unique_ptr<SyntheticCamera>> SyntheticCamera::create(
    render::Context& context, const vision::Camera& camera,
    const std::array<hand::HandModel, 2>& truth, const SyntheticCameraParams& params) {
  if (auto s = validate(params); !s) return s.error();
  if (truth[0].side != hand::Side::kLeft || truth[1].side != hand::Side::kRight)
    return Error{"synthetic camera: truth models must be {left, right}"};
  auto impl = std::make_unique<Impl>();
  if (auto st = impl->set_camera(camera); !st) return st.error();
  impl->params = params;
  AnatomicalHandParams k;
  k.forearm_length_m = params.forearm_length_m;
  k.bracelet_width_m = params.bracelet_width_m;
  k.bracelet_offset_m = params.bracelet_offset_m;
  k.skin_rgb = params.skin_rgb;
  k.nail_rgb = params.nail_rgb;
  k.bracelet_rgb = params.bracelet_rgb;
  auto meshes = std::make_shared<std::vector<MeshData>>();
  for (std::size_t h = 0; h < 2; ++h) {
    auto built = build_anatomical_hand(truth[h], k);
    if (!built) return Error{"synthetic camera: " + built.error().message};
    impl->hands[h] = std::move(built).value();
    impl->first_mesh[h] = meshes->size();
    for (MeshData& m : part_meshes(impl->hands[h])) meshes->push_back(std::move(m));
  }
  impl->meshes = meshes;
  auto renderer = render::Renderer::create(context, camera.width(), camera.height());
  if (!renderer) return renderer.error();
  impl->renderer = std::move(renderer).value();
  render::RenderParams& rp = impl->render_params;
  rp.background_rgb = params.screen_rgb;
  rp.hands = render::HandDrawMode::kVisible;  // hands in colour with their own skin/bracelet colours
  rp.hands_keep_colour = true;
  rp.light_dir_C = params.light_dir_C;
  rp.ambient = params.ambient;
  rp.depth_range = {0.02, 10.0};
  impl->rng = cv::RNG(params.seed);
  return std::unique_ptr<SyntheticCamera>(new SyntheticCamera(std::move(impl)));
}

const vision::Camera& SyntheticCamera::camera() const { return impl_->camera; }
Status SyntheticCamera::set_camera(const vision::Camera& camera) {
  if (camera.width() != impl_->camera.width() || camera.height() != impl_->camera.height())
    return Error{"synthetic camera: set_camera cannot change the image size"};
  return impl_->set_camera(camera);
}
const SyntheticCameraParams& SyntheticCamera::params() const { return impl_->params; }

Status SyntheticCamera::film(const HandPoses& poses, SyntheticFrame* out, const HandPoses* previous) {
  if (auto st = film_image(poses, out, previous); !st) return st;
  return film_truth(out);
}

Status SyntheticCamera::film_image(const HandPoses& poses, SyntheticFrame* out, const HandPoses* previous) {
  if (out == nullptr) return Error{"synthetic camera: no output frame given"};
  Impl& s = *impl_;
  s.truth_pending = false;
  const SyntheticCameraParams& p = s.params;
  const int samples = previous ? p.motion_blur_samples : 1;
  // Motion blur: sub-frames from the previous pose (exclusive) to the current one (last, so the
  // targets left in the renderer are the ground truth at `poses`).
  std::array<hand::HandParams, 2> blended;
  for (int k = 1; k <= samples; ++k) {
    HandPoses at = poses;
    if (k < samples) {
      const double t = static_cast<double>(k) / samples;
      for (int h = 0; h < 2; ++h) {
        if (!poses[h] || !(*previous)[h]) continue;
        blended[h] = *poses[h];
        blended[h].q = (1 - t) * (*previous)[h]->q + t * poses[h]->q;  // the little's own angles too
        if ((*previous)[h]->little_independent != poses[h]->little_independent)
          blended[h].set_little(poses[h]->little());  // unused before: no motion to blend
        at[h] = &blended[h];
      }
    }
    s.build_scene(at);
    if (auto st = s.renderer->render(s.scene, s.drawn, s.render_params); !st) return st;
    if (auto st = s.renderer->read(&s.targets, render::kColour); !st) return st;
    if (samples > 1) {
      if (k == 1) s.targets.colour.convertTo(s.accumulator, CV_32FC3);
      else cv::accumulate(s.targets.colour, s.accumulator);
    }
  }
  if (samples > 1) s.accumulator.convertTo(out->bgr, CV_8UC3, 1.0 / samples);
  else s.targets.colour.copyTo(out->bgr);

  out->toward_elbow_W = s.toward_elbow;

  // Optics and sensor: the lens bends the image (beyond the pinhole view the screen goes on), the
  // optics blur it, the sensor adds noise.
  if (s.lens) {
    const auto& c = p.screen_rgb;
    s.lens->distort(out->bgr, &s.through_lens, cv::Scalar(255.0 * c[2], 255.0 * c[1], 255.0 * c[0]));
    std::swap(out->bgr, s.through_lens);
  }
  if (p.psf_sigma_px > 0) cv::GaussianBlur(out->bgr, out->bgr, cv::Size(0, 0), p.psf_sigma_px);
  if (p.noise_sigma > 0) {
    // Gaussian noise from a bank a little larger than the frame, drawn once; each frame takes it
    // at a random offset (kNoisePad² different fields). Drawing 3·W·H normals per frame would
    // cost more than the rendering.
    constexpr int kNoisePad = 128;
    const cv::Size bank(out->bgr.cols + kNoisePad, out->bgr.rows + kNoisePad);
    if (s.noise_plus.size() != bank) {
      cv::Mat noise(bank, CV_16SC3);
      s.rng.fill(noise, cv::RNG::NORMAL, 0.0, p.noise_sigma);
      noise.convertTo(s.noise_plus, CV_8UC3);            // max(n, 0), saturated
      cv::Mat negative = -noise;
      negative.convertTo(s.noise_minus, CV_8UC3);        // max(−n, 0), saturated
    }
    const cv::Rect at(s.rng.uniform(0, kNoisePad), s.rng.uniform(0, kNoisePad), out->bgr.cols,
                      out->bgr.rows);
    cv::add(out->bgr, s.noise_plus(at), out->bgr);        // saturates at 255
    cv::subtract(out->bgr, s.noise_minus(at), out->bgr);  // saturates at 0
  }
  s.truth_pending = true;
  return Ok{};
}

Status SyntheticCamera::film_truth(SyntheticFrame* out) {
  if (out == nullptr) return Error{"synthetic camera: no output frame given"};
  Impl& s = *impl_;
  if (!s.truth_pending) return Error{"synthetic camera: film_truth without a film_image before it"};
  s.truth_pending = false;
  // Ground truth at the poses of the last film_image (its last render is still in the renderer).
  if (auto st = s.renderer->read(&s.targets, render::kHandDepth | render::kHandId); !st) return st;
  cv::compare(s.targets.hand_id, 0, out->mask, cv::CMP_GT);
  if (s.lut_index.empty()) {
    s.lut_index.create(1, 256, CV_8UC1);
    s.lut_only.create(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) {
      const render::HandId d = render::decode_hand_id(static_cast<std::uint8_t>(i));
      s.lut_index.at<std::uint8_t>(i) = i == 0 ? 0 : static_cast<std::uint8_t>(d.hand + 1);
      s.lut_only.at<std::uint8_t>(i) =
          i != 0 && d.finger != render::kBraceletPart && d.finger != render::kForearmPart ? 255 : 0;
    }
  }
  cv::LUT(s.targets.hand_id, s.lut_index, out->hand_index);
  cv::LUT(s.targets.hand_id, s.lut_only, out->hand_only);
  s.targets.hand_depth.copyTo(out->depth);
  s.targets.hand_id.copyTo(out->hand_id);
  return Ok{};
}

}  // namespace spidar::sim
