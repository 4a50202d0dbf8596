// The render test (`spidar-mr render-test`): the cube scene rendered headless from the rig
// camera, synthetic "real" hands filmed and composited in; PNGs of the first frame and a video.
#include "spidar/session/render_test.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>

#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/render/compositor.hpp"
#include "spidar/render/context.hpp"
#include "spidar/render/hand_shapes.hpp"
#include "spidar/render/overlay.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/data_path.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/strings/device_config.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/chroma_key.hpp"

namespace spidar::session {
namespace {

/// Both hands reaching over the cube, fingers curled; `phase` in [0, 1) moves them a little.
std::array<hand::HandParams, 2> grasp_poses(double phase) {
  const double s = std::sin(2 * std::numbers::pi * phase), c = std::cos(2 * std::numbers::pi * phase);
  hand::HandParams right;
  right.set_wrist(Vec3(0.125 + 0.006 * s, -0.05 + 0.006 * c, 0.035), Vec3(0.0, 0.0, 1.1));
  right[hand::kThumbCmcFlexion] = 0.35;
  right[hand::kThumbCmcAbduction] = 0.45;
  right[hand::kThumbIp] = 0.3;
  for (int p : {hand::kIndexMcpFlexion, hand::kMiddleMcpFlexion, hand::kRingMcpFlexion})
    right[p] = 0.55 + 0.15 * s;
  for (int p : {hand::kIndexDip, hand::kMiddleDip, hand::kRingDip}) right[p] = 0.45;
  return {hand::mirror_params(right), right};
}

}  // namespace

RenderTestResult run_render_test(const RenderTestParams& o) {
  const auto mode = render::parse_composite_mode(o.mode);
  if (!mode) throw SpidarError("--mode: " + mode.error().message);
  const vision::Camera camera = vision::load_camera_file(resolve_data_path(o.camera)).camera;
  const auto device = strings::load_device_config(resolve_data_path(o.device));
  auto world = physics::World::Load(resolve_data_path(o.scene));
  if (!world) throw SpidarError("--scene: " + world.error().message);

  auto context = render::Context::create_headless();
  if (!context) throw SpidarError(context.error().message);
  auto renderer = render::Renderer::create(**context, camera.width(), camera.height());
  if (!renderer) throw SpidarError(renderer.error().message);

  // Ground-truth hands: a user slightly smaller than the model's default hand.
  hand::HandDimensions truth_dims;
  truth_dims.length = 0.182;
  truth_dims.width = 0.081;
  const std::array<hand::HandModel, 2> truth = {
      hand::make_hand_model(hand::Side::kLeft, truth_dims).value(),
      hand::make_hand_model(hand::Side::kRight, truth_dims).value()};
  const std::array<hand::HandModel, 2> model = {hand::default_hand_model(hand::Side::kLeft),
                                                hand::default_hand_model(hand::Side::kRight)};
  sim::SyntheticCameraParams cam_params;
  cam_params.motion_blur_samples = o.motion_blur;
  auto synthetic = sim::SyntheticCamera::create(**context, camera, truth, cam_params);
  if (!synthetic) throw SpidarError("--motion-blur: " + synthetic.error().message);
  const auto keyer = vision::ChromaKeyer::create(vision::ChromaKeyParams{}).value();

  std::filesystem::create_directories(o.out);
  std::unique_ptr<render::VideoOutput> video;
  if (o.frames > 0) {
    auto v = render::VideoOutput::open(o.out + "/composite.mp4", camera.width(),
                                       camera.height(), o.fps);
    if (!v) throw SpidarError(v.error().message);
    video = std::move(v).value();
  }

  SceneSnapshot snapshot;
  render::RenderTargets targets;
  vision::ChromaKeyResult key;
  sim::SyntheticFrame frame;
  render::Compositor compositor;
  cv::Mat composite;
  std::array<hand::HandParams, 2> previous = grasp_poses(0);
  const int total = std::max(o.frames, 1);
  double ms_render = 0, ms_composite = 0, ms_film = 0;
  using Clock = std::chrono::steady_clock;
  auto ms_since = [](Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  for (int i = 0; i < total; ++i) {
    const auto truth_q = grasp_poses(static_cast<double>(i) / total);
    // Fingertips of the true hands drive the proxies (device finger order: left thumb..ring,
    // right thumb..ring); a few physics steps give the coupling forces for the overlay.
    std::vector<Vec3> tips, zero(8, Vec3::Zero());
    std::array<hand::HandRenderShapes, 2> model_shapes;
    for (int h = 0; h < 2; ++h) {
      const auto pts = hand::forward_kinematics(truth[h], truth_q[h]);
      for (const Vec3& p : pts.p_W_fingertip) tips.push_back(p);
      hand::HandParams fitted = truth_q[h];
      fitted[hand::kWristX] += 1e-3 * o.registration_error_mm;
      model_shapes[h] = hand::hand_render_shapes(model[h], fitted);
    }
    if (i == 0) (*world)->place_proxies(tips);
    for (int k = 0; k < 5; ++k) (*world)->step(tips, zero);

    auto t0 = Clock::now();
    const sim::HandPoses poses = {&truth_q[0], &truth_q[1]};
    const sim::HandPoses before = {&previous[0], &previous[1]};
    if (auto s = (*synthetic)->film(poses, &frame, i > 0 ? &before : nullptr); !s)
      throw SpidarError(s.error().message);
    ms_film += ms_since(t0);
    previous = truth_q;

    t0 = Clock::now();
    (*world)->snapshot(snapshot);
    for (const auto& shapes : model_shapes) render::append_hand_shapes(shapes, &snapshot);
    if (auto s = (*renderer)->render(snapshot, camera); !s) throw SpidarError(s.error().message);
    if (auto s = (*renderer)->read(&targets); !s) throw SpidarError(s.error().message);
    ms_render += ms_since(t0);

    t0 = Clock::now();
    if (auto s = keyer.apply(frame.bgr, &key); !s) throw SpidarError(s.error().message);
    render::CompositorParams cp;
    cp.mode = *mode;
    compositor.set_params(cp);
    render::CompositeInputs in{&targets, *mode == render::CompositeMode::kDepth ? key.foreground
                                                                                : frame.bgr,
                               key.alpha};
    if (auto s = compositor.compose(in, &composite); !s) throw SpidarError(s.error().message);
    ms_composite += ms_since(t0);
    if (video) {
      if (auto s = video->write(composite); !s) throw SpidarError(s.error().message);
    }

    if (i == 0) {  // the PNG set of the first frame
      auto png = [&](const std::string& name, const cv::Mat& m) {
        if (auto s = render::write_png(o.out + "/" + name, m); !s)
          throw SpidarError(s.error().message);
      };
      png("virtual.png", targets.colour);
      png("camera.png", frame.bgr);
      png("matte.png", key.silhouette);
      for (auto m : {render::CompositeMode::kDepth, render::CompositeMode::kPaper}) {
        render::CompositorParams p;
        p.mode = m;
        render::Compositor c(p);
        cv::Mat out;
        render::CompositeInputs mi{&targets,
                                   m == render::CompositeMode::kDepth ? key.foreground : frame.bgr,
                                   key.alpha};
        if (auto s = c.compose(mi, &out); !s) throw SpidarError(s.error().message);
        png(std::string("composite_") + render::composite_mode_name(m) + ".png", out);
      }
      cv::Mat overlay = composite.clone();
      std::vector<Vec3> fulcra, ends;
      for (std::size_t f = 0; f < device.fingers.size() && f < tips.size(); ++f)
        for (int k = 0; k < device.fingers[f].geometry.n; ++k) {
          fulcra.push_back(device.fingers[f].geometry.p_WA[static_cast<std::size_t>(k)]);
          ends.push_back(tips[f]);
        }
      render::draw_strings(overlay, camera, fulcra, ends);
      for (const auto& shapes : model_shapes) render::draw_hand_wireframe(overlay, camera, shapes);
      std::vector<Vec3> forces;  // the user feels the negative of the coupling force
      for (const Vec3& f : (*world)->coupling_forces()) forces.push_back(-f);
      render::draw_force_arrows(overlay, camera, tips, forces, 0.02);
      png("composite_overlay.png", overlay);
    }
  }
  RenderTestResult r;
  r.gl_renderer = (*context)->gl_renderer();
  r.mode = render::composite_mode_name(*mode);
  if (video) {
    video->close();
    r.video_path = video->path();
    r.video_format = render::video_format_name(video->format());
    r.video_frames = static_cast<int>(video->frames());
  }
  r.ms_film = ms_film / total;
  r.ms_render = ms_render / total;
  r.ms_composite = ms_composite / total;
  return r;
}

}  // namespace spidar::session
