// registration-study: the frame pipeline on the simulated user's hands, frame by frame and without
// a clock (deterministic): the scripted user's caps are exactly the script's goals, the synthetic
// camera films the user's anatomical hands, and the pipeline fits the model hands. Prints the
// ground-truth figures over the whole script and over its hard part (frames where the fit is
// worst: approach and release), so that model and registration changes can be compared on the
// same frames. Not a test (no assertions); a measuring instrument for issue 14's loss budget.
//
//   registration_study [--user PROFILE|--user-file FILE] [--model L,W | --model-user]
//                      [--silhouette] [--no-balls] [--no-wrist] [--personalise]
//                      [--t0 S] [--t1 S] [--fps F] [--verbose [--q-from S --q-to S]] [--ceiling-scan]
//                      [--dump DIR [--dump-below IOU]] [--bending-wrists [--oracle-forearm]]
//                      [--set KEY=VALUE]... [--cube X,Y,YAW] [--ring-on-side] [--fit-margin RAD]
//
// --ring-on-side --fit-margin 0.1: the scripted user's grasp as the session plays it (its
// defaults since 2026-11-29: the left ring finger on the cube's left face, the script fitted
// 0.1 rad inside the holding hand's joint ranges); without them, RubiksTaskParams' defaults.
//
// --cube: the cube elsewhere on the table, centre (X, Y) [m] and turned YAW [rad] about the
// vertical; the scripted user grasps it where it lies (RubiksTask::track), as in the demo with a
// scene whose cube is placed so.
//
// --oracle-forearm: the registration is told where the simulated forearms point
// (FramePipeline::set_forearm_directions), to measure what an estimate of that direction is worth.
//
// Besides the run's means it prints them second by second of the script (IoU against the ceiling,
// joints), so that the approach, the sizes' convergence and the release are seen apart.
//
// --set: a registration setting (configs/registration.yaml's keys, e.g. coverage_max_px=15) or,
// as shape.KEY, a personalisation one (shape.max_fingertip_cost=25), checked by the same parsers.
//
// --ceiling-scan: the model ceiling again with the skin's digits thicker or thinner (capsule radii
// × 0.9 … 1.3) and its palm fuller (palm_fullness), to see which shape parameter the ceiling's
// loss is in; and where the ceiling's missing (real hand, not model) and extra (model, not real
// hand) pixels are, by the model part nearest to them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "source_path.hpp"
#include "spidar/core/config.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/hand/forearm.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/registration/palm_breadth.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/registration/shape_estimator.hpp"
#include "spidar/registration/wrist_depth.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/render/renderer.hpp"
#include <opencv2/imgproc.hpp>
#include "spidar/sim/frame_truth.hpp"
#include "spidar/sim/model_ceiling.hpp"
#include "spidar/sim/rubiks_task.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/sim/user_hands.hpp"
#include "spidar/vision/bracelet.hpp"
#include "spidar/vision/vision_config.hpp"

using namespace spidar;

namespace {

struct Args {
  std::string user_profile = "user";
  std::string user_file;
  bool model_user = false;
  double model_length = 0, model_width = 0;
  /// --model-cap x,y,z: the model's fingertip-cap offset (HandDimensions::fingertip_offset) [m]
  std::optional<Vec3> model_cap;
  /// --cube X,Y,YAW: the cube's centre on the table [m] and its turn about the vertical [rad]
  /// (the user grasps it where it is, as in the demo with another scene)
  std::optional<Vec3> cube;
  bool silhouette = false, no_balls = false, no_wrist = false, personalise = false;
  double t0 = 0.3, t1 = 18.0, fps = 30.0;
  bool verbose = false;
  bool oracle = false;  ///< also fit each frame from the true pose, and compare the evidence
  double q_from = -1, q_to = 0.4;  ///< with --verbose, fit − truth parameters for frames in [q_from, q_to) [s]
  bool ceiling_scan = false;
  bool section_widths = false;  ///< --section-widths: the digits' sections against the model's, at the truth
  double forearm_cap = 0;  ///< --forearm-cap D: the model skin's forearm_cap_depth (0..1]
  double forearm_breadth = 0;  ///< --forearm-breadth B: the model skin's forearm_breadth
  bool model_bracelet = false;  ///< --model-bracelet: the model skin draws its bracelet
  std::vector<std::string> sets;  ///< --set key=value: a registration setting (registration.yaml)
  std::string dump_dir;  ///< --dump DIR: overlays of the frames whose IoU is below --dump-below
  double dump_below = 0.5;
  bool bending_wrists = false;  ///< --bending-wrists: the user's forearms point at fixed elbows (sim::user_elbows)
  bool oracle_forearm = false;  ///< --oracle-forearm: the registration is told where the true forearms point
  double shape_w = 0, shape_dq = 0;
  bool shape_silhouette = false;  ///< --shape-silhouette: the size estimator also fits the keyframes' spill
  bool ring_on_side = false;  ///< --ring-on-side: sim::RubiksTaskParams::ring_on_side (the session's grasp)
  double fit_margin = 0;      ///< --fit-margin RAD: fit_to_hands' limit margin, holding hand (the session's: 0.1)
};

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (k == "--user") a.user_profile = next();
    else if (k == "--user-file") a.user_file = next();
    else if (k == "--model-user") a.model_user = true;
    else if (k == "--model") std::sscanf(next().c_str(), "%lf,%lf", &a.model_length, &a.model_width);
    else if (k == "--model-cap" || k == "--cube") {
      // Three comma-separated numbers: the cap's x,y,z [m], or the cube's x,y [m] and yaw [rad].
      Vec3 c;
      if (std::sscanf(next().c_str(), "%lf,%lf,%lf", &c.x(), &c.y(), &c.z()) != 3 || !c.allFinite()) {
        std::fprintf(stderr, "registration_study: %s: expected %s\n", k.c_str(),
                     k == "--cube" ? "x,y,yaw [m, m, rad]" : "x,y,z [m]");
        return 2;
      }
      (k == "--cube" ? a.cube : a.model_cap) = c;
    }
    else if (k == "--silhouette") a.silhouette = true;
    else if (k == "--no-balls") a.no_balls = true;
    else if (k == "--no-wrist") a.no_wrist = true;
    else if (k == "--personalise") a.personalise = true;
    else if (k == "--shape-w") a.shape_w = std::atof(next().c_str());
    else if (k == "--shape-dq") a.shape_dq = std::atof(next().c_str());
    else if (k == "--shape-silhouette") a.shape_silhouette = true;
    else if (k == "--t0") a.t0 = std::atof(next().c_str());
    else if (k == "--t1") a.t1 = std::atof(next().c_str());
    else if (k == "--fps") a.fps = std::atof(next().c_str());
    else if (k == "--verbose") a.verbose = true;
    else if (k == "--oracle") a.oracle = true;
    else if (k == "--q-from") a.q_from = std::atof(next().c_str());
    else if (k == "--q-to") a.q_to = std::atof(next().c_str());
    else if (k == "--ceiling-scan") a.ceiling_scan = true;
    else if (k == "--section-widths") a.section_widths = true;
    else if (k == "--forearm-cap") a.forearm_cap = std::atof(next().c_str());
    else if (k == "--forearm-breadth") a.forearm_breadth = std::atof(next().c_str());
    else if (k == "--model-bracelet") a.model_bracelet = true;
    else if (k == "--dump") a.dump_dir = next();
    else if (k == "--bending-wrists") a.bending_wrists = true;
    else if (k == "--oracle-forearm") a.oracle_forearm = true;
    else if (k == "--dump-below") {
      const std::string v = next();
      char* end = nullptr;
      a.dump_below = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(a.dump_below >= 0 && a.dump_below <= 1)) {
        std::fprintf(stderr, "registration_study: --dump-below: expected an IoU in [0, 1], got '%s'\n", v.c_str());
        std::exit(2);
      }
    }
    else if (k == "--set") a.sets.push_back(next());
    else if (k == "--ring-on-side") a.ring_on_side = true;
    else if (k == "--fit-margin") a.fit_margin = std::atof(next().c_str());
    else {
      std::fprintf(stderr, "registration_study: unknown argument %s\n", k.c_str());
      return 2;
    }
  }
  auto ctx = render::Context::create_headless();
  if (!ctx) {
    std::fprintf(stderr, "no headless OpenGL: %s\n", ctx.error().message.c_str());
    return 1;
  }
  auto& context = *ctx.value();
  const auto profiles = hand::load_hand_profiles(
      a.user_file.empty() ? test::source("configs/hands.yaml") : a.user_file);
  const auto* user = profiles.find(a.user_profile);
  if (!user) user = &profiles.profiles.front();
  const std::array<hand::HandModel, 2> truth_models{user->model(hand::Side::kLeft),
                                                    user->model(hand::Side::kRight)};
  std::array<hand::HandModel, 2> models{hand::default_hand_model(hand::Side::kLeft),
                                        hand::default_hand_model(hand::Side::kRight)};
  if (a.model_user) models = truth_models;
  if (a.model_length > 0) {
    hand::HandDimensions d = models[0].shape.dimensions;
    d.length = a.model_length;
    d.width = a.model_width;
    models = {hand::make_hand_model(hand::Side::kLeft, d).value(),
              hand::make_hand_model(hand::Side::kRight, d).value()};
  }
  if (a.model_cap) {
    for (auto& m : models) {
      hand::HandDimensions d = m.shape.dimensions;
      d.fingertip_offset = *a.model_cap;
      m.shape = hand::make_hand_shape(d).value();
    }
  }
  const vision::Camera camera = vision::default_rig_camera();
  render::HandSkinParams model_skin = pipeline::FramePipelineParams{}.model_skin;
  if (a.forearm_cap > 0) model_skin.forearm_cap_depth = a.forearm_cap;
  if (a.forearm_breadth > 0) model_skin.forearm_breadth = a.forearm_breadth;
  if (a.model_bracelet) model_skin.bracelet = true;
  auto ceiling = sim::ModelCeiling::create(context, camera, truth_models, model_skin).value();

  // The ceiling's variants (--ceiling-scan): digit radii scaled, then the palm's fullness.
  struct Variant {
    std::string name;
    std::unique_ptr<sim::ModelCeiling> ceiling;
    std::vector<double> iou;
  };
  std::vector<Variant> variants;
  if (a.ceiling_scan) {
    // One variant: the hands `hands` drawn with `skin`, named by printf(format, value).
    auto add = [&](const std::array<hand::HandModel, 2>& hands, const render::HandSkinParams& skin,
                   const char* format, double value) {
      char name[96];
      std::snprintf(name, sizeof name, format, value);
      variants.push_back({name, sim::ModelCeiling::create(context, camera, hands, skin).value(), {}});
    };
    for (double scale : {0.9, 1.1, 1.2, 1.3}) {
      std::array<hand::HandModel, 2> thick = truth_models;
      for (auto& m : thick)
        for (auto& d : m.shape.digits)
          for (double& r : d.radius) r *= scale;
      add(thick, model_skin, "digit radii x%.1f", scale);
    }
    // The skin before 2026-11-24: the forearm's hemispherical end filled the carpus.
    render::HandSkinParams before = model_skin;
    before.forearm_cap_depth = 1.0;
    before.palm_reaches_wrist = false;
    before.palm_wrist_breadth = 1.0;
    before.forearm_breadth = 0.62;
    before.forearm_depth = 1.0;
    add(truth_models, before, "a hemispherical forearm end, the palm from the carpus", 0);
    // One skin parameter at a time.
    struct Setting {
      double render::HandSkinParams::*field;
      const char* format;
      std::vector<double> values;
    };
    for (const Setting& set : {Setting{&render::HandSkinParams::forearm_cap_depth, "forearm cap depth %.2f", {0.1, 0.5}},
                               Setting{&render::HandSkinParams::palm_wrist_breadth, "palm breadth at the wrist %.1f", {1.0, 0.9, 0.7}},
                               Setting{&render::HandSkinParams::palm_fullness, "palm fullness %.1f", {1.0, 1.5, 1.8}},
                               Setting{&render::HandSkinParams::forearm_breadth, "forearm breadth %.2f", {0.62, 0.75}},
                               Setting{&render::HandSkinParams::forearm_depth, "forearm depth %.2f", {1.0, 0.8, 0.5}}}) {
      for (double v : set.values) {
        render::HandSkinParams skin = model_skin;
        skin.*set.field = v;
        add(truth_models, skin, set.format, v);
      }
    }
  }

  // Parts of the ceiling's loss (--ceiling-scan): the model skin at the truth, by part.
  std::unique_ptr<render::Renderer> part_renderer;
  std::array<render::HandSkin, 2> part_skins;
  auto part_meshes = std::make_shared<std::vector<MeshData>>();
  const render::HandSkinParams part_skin_params = model_skin;
  // [0..4] digits, 5 palm, 6 wrist (forearm or bracelet of the model): missing and extra pixels.
  std::array<double, 7> part_missing{}, part_extra{};
  double missing_under_forearm = 0;  // real hand pixels the model covers with its forearm or bracelet
  double part_real = 0;
  if (a.ceiling_scan) {
    for (int h = 0; h < 2; ++h)
      part_skins[h] = render::build_hand_skin(truth_models[h], part_skin_params, part_meshes.get());
    part_renderer = render::Renderer::create(context, camera.width(), camera.height()).value();
  }
  auto part_of = [](std::uint8_t id) {
    const render::HandId d = render::decode_hand_id(id);
    if (d.finger >= 0 && d.finger <= 4) return d.finger;
    return d.finger == render::kPalmPart ? 5 : 6;
  };

  const auto vc = vision::load_vision_config(test::source("configs/vision.yaml"));
  pipeline::FramePipelineParams p;
  p.chroma_key = vc.chroma_key;
  p.bracelet = vc.bracelet;
  // --set key=value: any key of configs/registration.yaml's registration section, or of its
  // personalisation section as shape.KEY, through the same parsers (ranges, file:line errors);
  // silhouette_downsample is the pipeline's own.
  std::string registration_yaml = "registration: {}\n", shape_yaml = "personalisation: {}\n";
  std::string reg_keys, shape_keys;
  for (const std::string& kv : a.sets) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "registration_study: --set %s: expected key=value\n", kv.c_str());
      return 2;
    }
    const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
    if (key == "silhouette_downsample") p.silhouette_downsample = std::atoi(value.c_str());
    else if (key == "other_depth_every") p.other_depth_every = std::atoi(value.c_str());
    else if (key == "other_depth_rounds") p.other_depth_rounds = std::atoi(value.c_str());
    else if (key == "other_depth_keep") p.other_depth_keep = std::atof(value.c_str());
    else if (key == "other_depth_confirm") p.other_depth_confirm = std::atoi(value.c_str()) != 0;
    else if (key == "passive_range") p.passive_range = std::atoi(value.c_str()) != 0;
    else if (key.rfind("shape.", 0) == 0) shape_keys += "  " + key.substr(6) + ": " + value + "\n";
    else reg_keys += "  " + key + ": " + value + "\n";
  }
  if (!reg_keys.empty()) registration_yaml = "registration:\n" + reg_keys;
  if (!shape_keys.empty()) shape_yaml = "personalisation:\n" + shape_keys;
  try {
    p.registration = registration::parse_registration_params(
        core::ConfigNode::Parse(registration_yaml, "--set")["registration"]);
    p.shape_estimator = registration::parse_shape_estimator_params(
        core::ConfigNode::Parse(shape_yaml, "--set")["personalisation"], nullptr);
  } catch (const core::ConfigError& e) {
    std::fprintf(stderr, "registration_study: %s\n", e.what());
    return 2;
  }
  p.registration.silhouette_term = p.registration.silhouette_term || a.silhouette;
  if (a.no_balls) p.registration.joint_ball_sigma_px = 1000;
  if (a.no_wrist) p.registration.wrist_sigma_px = 1000;
  p.personalise_shape = a.personalise;
  p.model_skin = model_skin;
  if (a.shape_w > 0) p.shape_estimator.solve_every = static_cast<int>(a.shape_w);
  if (a.shape_dq > 0) p.shape_estimator.min_pose_change = a.shape_dq;
  if (a.shape_silhouette) p.shape_estimator.silhouette = registration::ShapeSilhouette::kSpill;
  sim::RubiksTaskParams task_params;
  core::Latest<sim::CubePoseSample> cube_pose;
  Pose X_W_cube;
  if (a.cube) {
    X_W_cube.p = Vec3(a.cube->x(), a.cube->y(), 0.0);
    X_W_cube.R = Quat(Eigen::AngleAxisd(a.cube->z(), Vec3::UnitZ()));
    task_params.p_W_cube = X_W_cube.p;
    sim::CubePoseSample sample;
    sample.p_W = {X_W_cube.p.x(), X_W_cube.p.y(), X_W_cube.p.z()};
    sample.q_WC = {X_W_cube.R.w(), X_W_cube.R.x(), X_W_cube.R.y(), X_W_cube.R.z()};
    cube_pose.publish(sample);
  }
  task_params.ring_on_side = a.ring_on_side;
  sim::RubiksTask task(task_params);
  task.fit_to_hands(truth_models, 0.01, std::array<double, 2>{a.fit_margin, 0.0});
  if (a.cube) task.track(&cube_pose);
  sim::SyntheticCameraParams film_params;
  if (a.bending_wrists) film_params.elbows_W = sim::user_elbows(task);
  auto film = sim::SyntheticCamera::create(context, camera, truth_models, film_params).value();
  for (int h = 0; h < 2; ++h)
    p.initial_r_W_hand[h] =
        task.nominal(a.t0, h == 0 ? hand::Side::kLeft : hand::Side::kRight).r_W_hand();
  auto pipe = pipeline::FramePipeline::create(context, camera, models, p).value();
  // --oracle: a second pipeline, warm-started at the true pose every frame (no size estimate).
  pipeline::FramePipelineParams oracle_p = p;
  oracle_p.personalise_shape = false;
  auto oracle = a.oracle ? pipeline::FramePipeline::create(context, camera, models, oracle_p).value() : nullptr;
  pipeline::FrameResult oracle_r;
  std::array<int, 2> oracle_better{}, oracle_n{};
  std::array<double, 2> oracle_depth_sum{}, tracked_depth_sum{};
  std::vector<double> oracle_iou, oracle_joint;  // the fits from the truth: IoU, joint error [px]
  // Per hand and frame: the evidence of the tracked fit and of the fit from the truth.
  std::array<std::vector<double>, 2> oracle_e_tracked, oracle_e_truth;
  // Per hand, summed over frames: each term's cost (fingertip, wrist, joint-ball, silhouette) of
  // the tracked fit minus the fit from the truth, over the frames where the tracked fit is the
  // cheaper, and where it is not.
  std::array<std::array<double, 4>, 2> oracle_term_diff_cheaper{}, oracle_term_diff_dearer{};
  sim::FrameTruthWorkspace oracle_ws;
  sim::UserHands hands(truth_models, task);

  SceneSnapshot scene;  // a cube where the user grasps
  Shape cube;
  cube.type = Shape::Type::kBox;
  cube.size = Vec3(0.0285, 0.0285, 0.0285);
  cube.rgba = {0.9f, 0.9f, 0.9f, 1.f};
  cube.body = 1;
  cube.X_WS = X_W_cube;
  scene.shapes.push_back(cube);

  sim::SyntheticFrame frame;
  pipeline::FrameResult r;
  sim::FrameTruthWorkspace ws;
  std::array<double, 6> brace_k{};
  std::vector<double> brace_term;
  std::vector<double> brace_pred;  // the detector's midpoint predicted from the true band (bracelet_midpoint_px)
  std::vector<double> brace_term_where_pred;  // brace_term on the frames brace_pred has (like for like)
  std::array<double, 6> joint_part_sum{}, joint_floor_sum{}, joint_part_n{};  // wrist, thumb … little
  int brace_n = 0;
  std::vector<double> brace_axis, brace_surf, obs, caps, iou, tip, joint, ceil_iou, contested, contested_paper;
  std::array<double, 2> iterations{};  // linear solves, summed over the frames
  int kept_restarts = 0, kept_switches = 0, kept_reaches = 0;
  std::vector<double> frame_t;  // each scored frame's time on the script [s]
  std::array<std::vector<double>, 2> wrist_depth_mm;  // fit − truth along the camera's axis, per hand
  // The angle between the forearm direction the fit used and the simulated forearm's [°], per hand.
  std::array<std::vector<double>, 2> forearm_err_deg;
  std::array<Vec3, 2> palm_rot{Vec3::Zero(), Vec3::Zero()};  // |rotation error| about x_H, y_H, z_H [° sums]
  std::array<double, 2> palm_n{};
  std::array<std::vector<double>, 2> palm_roll_deg;  // signed, about y_H
  // Each finger parameter's error (fit − truth) per hand and frame [rad], for its bias, its spread
  // and how it moves with the palm's roll.
  std::array<std::array<std::vector<double>, hand::kParamCount>, 2> param_err;
  // Joint error by digit and joint along it (fit, and the floor as above) [px sums], and counts.
  std::array<std::array<double, 4>, 5> joint_at_sum{}, joint_at_floor{}, joint_at_n{};
  std::vector<double> chord_ratio;  // the real palm's chord / the model's, at the truth
  // --section-widths: the real digits' sections / the model's diameters at the truth: proximal,
  // middle (the thumb's none), distal phalanges, all.
  std::array<std::vector<double>, 4> section_ratio;
  // The fits' evidence cost per hand and frame (TermCosts, without the prior): total, fingertip,
  // wrist, joint-ball, silhouette.
  std::array<std::vector<double>, 5> evidence_terms;
  int depth_switches = 0, restarts = 0;  // the pipeline's wrist-depth switches and restarts
  std::array<Vec3, 8> g;
  for (double t = a.t0; t < a.t1 && !task.finished(t); t += 1.0 / a.fps) {
    // The device's caps: at the face, pressed a fifth of the squeeze in (the displayed force
    // holds the fingers near the touching positions; about what the demo's caps show).
    std::array<Vec3, 8> touch;
    task.goals(t, g);
    task.touch_points(t, touch);
    for (int f = 0; f < 8; ++f) g[f] = touch[f] + 0.2 * (g[f] - touch[f]);
    hands.update(t, g);
    device::FingertipSample s;
    s.finger_count = 8;
    s.t_ns = std::llround(t * 1e9);  // the script's time: the pipeline's speeds and motion model use it
    for (int f = 0; f < 8; ++f) s.p_W[f] = {g[f].x(), g[f].y(), g[f].z()};
    const auto& truth = hands.params();
    if (!film->film({&truth[0], &truth[1]}, &frame).ok()) return 1;
    if (a.oracle_forearm) pipe->set_forearm_directions(frame.toward_elbow_W);
    if (auto st = pipe->process(frame.bgr, s, scene, &r); !st.ok()) {
      std::fprintf(stderr, "%s\n", st.error().message.c_str());
      return 1;
    }
    if (oracle) {
      if (a.personalise) oracle->use_model_sizes(r.models);
      if (!oracle->warm_start(truth).ok() ||
          !oracle->process(frame.bgr, s, scene, &oracle_r).ok())
        return 1;
      const auto mo = sim::measure_frame(frame, oracle_r, p.compositor.mode, oracle_r.models, truth_models, truth,
                                         camera, &oracle_ws).value();
      oracle_iou.push_back(mo.iou);
      oracle_joint.push_back(0.5 * (mo.joint_px[0] + mo.joint_px[1]));
      for (int h = 0; h < 2; ++h) {
        const double d_true = camera.depth(hand::hand_pose(truth[h]).p);
        const double e_t = r.fits[h].terms.evidence(), e_o = oracle_r.fits[h].terms.evidence();
        const double dd_t = 1e3 * (camera.depth(hand::hand_pose(r.hands[h]).p) - d_true);
        const double dd_o = 1e3 * (camera.depth(hand::hand_pose(oracle_r.hands[h]).p) - d_true);
        ++oracle_n[h];
        oracle_e_tracked[h].push_back(e_t);
        oracle_e_truth[h].push_back(e_o);
        {
          const auto& a_t = r.fits[h].terms;
          const auto& a_o = oracle_r.fits[h].terms;
          const std::array<double, 4> d{a_t.fingertip - a_o.fingertip, a_t.wrist - a_o.wrist,
                                        a_t.joint_ball - a_o.joint_ball, a_t.silhouette - a_o.silhouette};
          auto& into = e_t < e_o ? oracle_term_diff_cheaper[h] : oracle_term_diff_dearer[h];
          for (int k = 0; k < 4; ++k) into[static_cast<std::size_t>(k)] += d[static_cast<std::size_t>(k)];
        }
        oracle_better[h] += e_o < e_t;
        oracle_depth_sum[h] += std::abs(dd_o);
        tracked_depth_sum[h] += std::abs(dd_t);
        if (a.verbose)
          std::printf("  oracle %d: evidence tracked %.3f (depth %+.0f mm), from the truth %.3f (depth %+.0f mm)\n",
                      h, e_t, dd_t, e_o, dd_o);
      }
    }
    depth_switches += r.depth_switches;
    if (a.verbose) {  // the wrist's other depth the pipeline would try (registration/wrist_depth.hpp)
      for (int h = 0; h < 2; ++h) {
        registration::HandObservation o;
        for (int f = 0; f < 4; ++f) {
          o.p_W_fingertip[f] = g[4 * h + f];
          o.fingertip_valid[f] = true;
        }
        if (r.bracelets[h].found) o.wrist_px = r.bracelets[h].wrist_px;
        const auto other = registration::other_wrist_depth(r.models[h], r.hands[h], o, camera);
        const double d_true = camera.depth(hand::hand_pose(truth[h]).p);
        std::printf("  other depth %d: fit %+.0f mm, other %s%+.0f mm\n", h,
                    1e3 * (camera.depth(hand::hand_pose(r.hands[h]).p) - d_true), other ? "" : "none ",
                    other ? 1e3 * (camera.depth(hand::hand_pose(*other).p) - d_true) : 0.0);
      }
    }
    restarts += r.restarts;
    const auto m = sim::measure_frame(frame, r, p.compositor.mode, r.models, truth_models, truth,
                                      camera, &ws).value();
    const double c = ceiling->iou(truth, frame.hand_only, frame.toward_elbow_W).value();
    // The palm chord's evidence at the truth (palm_breadth.hpp): the real palm's chord against the
    // model palm's, both at the true pose and sizes.
    for (int h = 0; h < 2; ++h)
      if (const auto ch = registration::measure_palm_chord(truth_models[h], truth[h], camera, frame.hand_only,
                                                           nullptr, 1, p.shape_estimator.palm_chord))
        chord_ratio.push_back(ch->measured_px / registration::model_palm_chord_px(truth_models[h], truth[h], camera,
                                                                                ch->at, ch->across_px));
    for (Variant& v : variants) v.iou.push_back(v.ceiling->iou(truth, frame.hand_only, frame.toward_elbow_W).value());
    // The digits' sections at the truth (--section-widths): the real digit's silhouette across
    // each phalanx against the model capsule's diameter, both at the true pose and sizes, on the
    // hand's own pixels (so that the other hand does not widen a section).
    if (a.section_widths) {
      registration::RegistrationParams sp = p.registration;
      sp.silhouette_term = true;
      sp.digit_axis_sigma_px = 5.0;
      for (int h = 0; h < 2; ++h) {
        const cv::Mat own = frame.hand_index == h + 1;
        registration::ImageEvidence ev;
        ev.camera = &camera;
        ev.alpha = own;
        registration::HandObservation no_obs;
        const registration::ResidualProblem pr{&truth_models[h], &no_obs, &ev, nullptr, &sp};
        registration::FrozenTargets tg;
        registration::freeze_targets(pr, truth[h], &tg);
        for (int k = 0; k < tg.axis_count; ++k) {
          const auto& ap = tg.axes[static_cast<std::size_t>(k)];
          const auto bone = registration::silhouette_bone(ap.bone);
          section_ratio[static_cast<std::size_t>(bone.segment == 3 || (bone.finger == 0 && bone.segment == 2) ? 2 : bone.segment - 1)]
              .push_back(ap.width_px / ap.model_width_px);
          section_ratio[3].push_back(ap.width_px / ap.model_width_px);
        }
      }
    }
    if (part_renderer) {
      SceneSnapshot hands_scene;
      hands_scene.meshes = part_meshes;
      for (int h = 0; h < 2; ++h) {
        const auto& bent = frame.toward_elbow_W[static_cast<std::size_t>(h)];
        render::pose_hand_skin(truth_models[h], part_skins[h], truth[h], part_skin_params, &hands_scene,
                               bent ? &*bent : nullptr);
      }
      render::RenderParams rp;
      rp.hands = render::HandDrawMode::kHidden;
      render::RenderTargets tg;
      if (!part_renderer->render(hands_scene, camera, rp).ok() || !part_renderer->read(&tg, render::kHandId).ok())
        return 1;
      // Nearest model pixel (any part) of every pixel: labels of the zero pixels of `empty`.
      cv::Mat empty = tg.hand_id == 0, dist, labels;
      cv::distanceTransform(empty, dist, labels, cv::DIST_L2, 3, cv::DIST_LABEL_PIXEL);
      std::vector<std::uint8_t> label_id(static_cast<std::size_t>(tg.hand_id.total()) + 1, 0);
      for (int y = 0; y < tg.hand_id.rows; ++y)
        for (int x = 0; x < tg.hand_id.cols; ++x)
          if (tg.hand_id.at<std::uint8_t>(y, x) != 0)
            label_id[static_cast<std::size_t>(labels.at<int>(y, x))] = tg.hand_id.at<std::uint8_t>(y, x);
      if (!a.dump_dir.empty() && std::fmod(t + 1e-6, 2.0) < 1.0 / a.fps) {
        // Green: real hand only; red: model hand only; yellow: both; blue: model forearm over
        // real hand; grey: the rest of the model's forearm.
        cv::Mat o(tg.hand_id.size(), CV_8UC3, cv::Scalar(0, 0, 0));
        for (int y = 0; y < o.rows; ++y)
          for (int x = 0; x < o.cols; ++x) {
            const std::uint8_t id = tg.hand_id.at<std::uint8_t>(y, x);
            const bool real = frame.hand_only.at<std::uint8_t>(y, x) != 0;
            const bool arm = id != 0 && part_of(id) == 6, model = id != 0 && !arm;
            cv::Vec3b colour(0, 0, 0);
            if (real && model) colour = {0, 220, 220};
            else if (real && arm) colour = {255, 80, 0};
            else if (real) colour = {0, 200, 0};
            else if (model) colour = {0, 0, 220};
            else if (arm) colour = {90, 90, 90};
            o.at<cv::Vec3b>(y, x) = colour;
          }
        cv::Mat row;
        cv::hconcat(frame.bgr, o, row);
        char name[64];
        std::snprintf(name, sizeof name, "/ceiling_t%05.2f.png", t);
        cv::imwrite(a.dump_dir + name, row);
      }
      for (int y = 0; y < tg.hand_id.rows; ++y) {
        for (int x = 0; x < tg.hand_id.cols; ++x) {
          const std::uint8_t id = tg.hand_id.at<std::uint8_t>(y, x);
          const bool real = frame.hand_only.at<std::uint8_t>(y, x) != 0;
          const bool model = id != 0 && part_of(id) != 6;
          part_real += real;
          if (model && !real) part_extra[static_cast<std::size_t>(part_of(id))] += 1;
          if (real && !model && id != 0) missing_under_forearm += 1;
          if (real && !model) {
            const std::uint8_t near = id != 0 ? id : label_id[static_cast<std::size_t>(labels.at<int>(y, x))];
            part_missing[static_cast<std::size_t>(near == 0 ? 6 : part_of(near))] += 1;
          }
        }
      }
    }
    // Fitted caps to the strings' caps, and the truth's caps to the strings' (the user's IK).
    double obs_res = 0, cap_res = 0;
    for (int h = 0; h < 2; ++h) {
      const auto fit_pts = hand::forward_kinematics(r.models[h], r.hands[h]);
      const auto true_pts = hand::forward_kinematics(truth_models[h], truth[h]);
      for (int f = 0; f < 4; ++f) {
        obs_res += (fit_pts.p_W_fingertip[f] - g[4 * h + f]).norm() / 8;
        cap_res += (true_pts.p_W_fingertip[f] - g[4 * h + f]).norm() / 8;
      }
    }
    if (a.verbose && t >= a.q_from && t < a.q_to) {
      for (int h = 0; h < 2; ++h) {
        const auto mt = hand::forward_kinematics(r.models[h], truth[h]);
        std::printf("  hand %d model at truth, caps off [mm]:", h);
        for (int f = 0; f < 4; ++f) std::printf(" %.2f", 1e3 * (mt.p_W_fingertip[f] - g[4 * h + f]).norm());
        std::printf("  outside limits:");
        const auto& lim = r.models[h].limits;
        for (int k = 6; k < hand::kParamCount; ++k)
          if (truth[h][k] < lim.lower[k] - 1e-6 || truth[h][k] > lim.upper[k] + 1e-6) std::printf(" %d (%.3f in [%.3f, %.3f])", k, truth[h][k], lim.lower[k], lim.upper[k]);
        std::printf("  fit-truth q:");
        for (int k = 0; k < hand::kParamCount; ++k) std::printf(" %.2f", r.hands[h][k] - truth[h][k]);
        std::printf("\n");
      }
    }
    if (a.verbose && cap_res > 0.002) {
      for (int h = 0; h < 2; ++h) {
        const auto true_pts = hand::forward_kinematics(truth_models[h], truth[h]);
        std::printf("  hand %d caps off [mm]:", h);
        for (int f = 0; f < 4; ++f) std::printf(" %.1f", 1e3 * (true_pts.p_W_fingertip[f] - g[4 * h + f]).norm());
        std::printf("  at limits:");
        const auto& lim = truth_models[h].limits;
        for (int k = 6; k < hand::kParamCount; ++k)
          if (truth[h][k] <= lim.lower[k] + 1e-6 || truth[h][k] >= lim.upper[k] - 1e-6) std::printf(" %d", k);
        std::printf("\n");
      }
    }
    // The bracelet's detected midpoint against the projection of the truth's band centre (on the
    // forearm's axis) and of the band's visible surface centre (toward the camera).
    for (int h = 0; h < 2; ++h) {
      if (!r.bracelets[h].found) continue;
      // The band sits bracelet_offset_m along the forearm (which points at the elbow with bending
      // wrists, else along −y_H).
      const Pose X_WH = hand::hand_pose(truth[h]);
      const auto& bent = frame.toward_elbow_W[static_cast<std::size_t>(h)];
      const Vec3 axis = bent ? Vec3(-*bent) : Vec3(X_WH.R * Vec3::UnitY());
      const Vec3 p_WB = X_WH.p - film_params.bracelet_offset_m * axis;
      Vec3 n = camera.X_WC().p - p_WB;
      n -= n.dot(axis) * axis;
      n.normalize();
      const double radius = 0.31 * truth_models[h].shape.dimensions.width + 0.002;
      const Vec2 det = r.bracelets[h].wrist_px;
      brace_axis.push_back((det - camera.project(p_WB)).norm());
      brace_surf.push_back((det - camera.project(p_WB + (2.0 / 3.14159265) * radius * n)).norm());
      // The wrist term's own expectation, at the true pose and sizes (its residual, in px).
      brace_term.push_back((det - camera.project(registration::bracelet_visible_point(
                                      X_WH, truth_models[h].shape.dimensions.width, camera.X_WC().p,
                                      p.registration, nullptr))).norm());
      if (const auto mid = registration::bracelet_midpoint_px(hand::forearm_pose(X_WH, -axis),
                                                              truth_models[h].shape.dimensions.width, camera,
                                                              p.registration)) {
        brace_pred.push_back((det - *mid).norm());
        brace_term_where_pred.push_back(brace_term.back());
      }
      for (int k = 0; k < 6; ++k)
        brace_k[k] += (det - camera.project(p_WB + 0.2 * k * radius * n)).norm();
      ++brace_n;
    }
    if (std::getenv("THICK_DBG")) {
      // Predicted band extents at a pose: the band's near-side surface sampled (ellipse section,
      // 18 mm along the forearm), projected; extent along the detected long axis and across it.
      auto extents = [&](const hand::HandParams& q, double width, const vision::BraceletObservation& b) {
        const Pose X = hand::hand_pose(q);
        const Mat3 R = X.R.toRotationMatrix();
        const Vec3 x = R.col(0), y = R.col(1), z = R.col(2);
        const double ra = p.registration.bracelet_radius_per_width * width + p.registration.bracelet_standoff_m;
        const double rb = p.registration.bracelet_depth_ratio * p.registration.bracelet_radius_per_width * width + p.registration.bracelet_standoff_m;
        Vec2 ax = (b.end_b_px - b.end_a_px).normalized();
        Vec2 n(-ax.y(), ax.x());
        double lo_a = 1e9, hi_a = -1e9, lo_n = 1e9, hi_n = -1e9;
        const Vec3 cam = camera.X_WC().p;
        for (int i = 0; i < 72; ++i) {
          const double phi = 2 * 3.14159265 * i / 72;
          const Vec3 radial = ra * std::cos(phi) * x + rb * std::sin(phi) * z;
          const Vec3 normal = (std::cos(phi) / ra) * x + (std::sin(phi) / rb) * z;
          for (double sl : {0.012 - 0.009, 0.012 + 0.009}) {
            const Vec3 pt = X.p - sl * y + radial;
            if (normal.dot(cam - pt) <= 0) continue;  // the far side
            const Vec2 uv = camera.project(pt);
            lo_a = std::min(lo_a, uv.dot(ax)); hi_a = std::max(hi_a, uv.dot(ax));
            lo_n = std::min(lo_n, uv.dot(n)); hi_n = std::max(hi_n, uv.dot(n));
          }
        }
        return Vec2(hi_a - lo_a, hi_n - lo_n);
      };
      for (int h = 0; h < 2; ++h) {
        const auto& b = r.bracelets[h];
        if (!b.found) continue;
        const Vec2 et = extents(truth[h], truth_models[h].shape.dimensions.width, b);
        const Vec2 ef = extents(r.hands[h], r.models[h].shape.dimensions.width, b);
        std::printf("TH t %.2f h %d fill %.2f obs %.0f x %.1f truth %.0f x %.1f fit %.0f x %.1f depth %+.0f\n", t, h, b.fill,
                    b.length_px, b.thickness_px, et.x(), et.y(), ef.x(), ef.y(),
                    1e3 * (camera.depth(hand::hand_pose(r.hands[h]).p) - camera.depth(hand::hand_pose(truth[h]).p)));
      }
    }
    if (!a.dump_dir.empty() && m.iou < a.dump_below) {
      // Green: the real hands only; red: the fitted model's hand pixels; the frame beside.
      cv::Mat overlay(frame.hand_only.size(), CV_8UC3, cv::Scalar(0, 0, 0));
      overlay.setTo(cv::Scalar(0, 200, 0), frame.hand_only);
      cv::Mat both;
      cv::bitwise_and(frame.hand_only, ws.model_mask, both);
      overlay.setTo(cv::Scalar(0, 0, 220), ws.model_mask);
      overlay.setTo(cv::Scalar(0, 220, 220), both);
      // Joints: the truth's white, the fit's magenta, joined.
      for (int h = 0; h < 2; ++h) {
        const auto fit_pts = hand::forward_kinematics(r.models[h], r.hands[h]);
        const auto true_pts = hand::forward_kinematics(truth_models[h], truth[h]);
        for (std::size_t j = 0; j < fit_pts.p_W_joint.size(); ++j) {
          const Vec2 a2 = camera.project(true_pts.p_W_joint[j]), b2 = camera.project(fit_pts.p_W_joint[j]);
          if (!a2.allFinite() || !b2.allFinite() || a2.cwiseAbs().maxCoeff() > 1e4 || b2.cwiseAbs().maxCoeff() > 1e4)
            continue;  // behind the camera or far outside the image
          const cv::Point pa(static_cast<int>(a2.x()), static_cast<int>(a2.y()));
          const cv::Point pb(static_cast<int>(b2.x()), static_cast<int>(b2.y()));
          cv::line(overlay, pa, pb, cv::Scalar(255, 255, 255), 1);
          cv::circle(overlay, pa, 2, cv::Scalar(255, 255, 255), -1);
          cv::circle(overlay, pb, 2, cv::Scalar(255, 0, 255), -1);
        }
      }
      cv::Mat row;
      cv::hconcat(frame.bgr, overlay, row);
      char name[64];
      std::snprintf(name, sizeof name, "/t%05.2f.png", t);
      cv::imwrite(a.dump_dir + name, row);
    }
    // How far along the camera's axis the fitted wrist is from the true one (the direction the
    // strings and the bracelet's point observe least; measure_frame's).
    for (int h = 0; h < 2; ++h) wrist_depth_mm[h].push_back(m.wrist_depth_mm[h]);
    for (int h = 0; h < 2; ++h) {
      const auto& bent = frame.toward_elbow_W[static_cast<std::size_t>(h)];
      const Vec3 truth_dir = bent ? *bent : Vec3(-(hand::hand_pose(truth[h]).R * Vec3::UnitY()));
      forearm_err_deg[h].push_back(std::acos(std::clamp(truth_dir.normalized().dot(r.toward_elbow_W[h]), -1.0, 1.0)) *
                                   180.0 / units::kPi);
    }
    for (int h = 0; h < 2; ++h) {
      const Mat3 Rf = hand::hand_pose(r.hands[h]).R.toRotationMatrix(), Rt = hand::hand_pose(truth[h]).R.toRotationMatrix();
      // The fit's palm in the truth's frame, as a rotation vector in H (x across the palm, y along
      // it toward the fingers, z out of its back): how far it is turned about each of its axes.
      const Eigen::AngleAxisd d(Rt.transpose() * Rf);
      const Vec3 v = d.angle() * d.axis();
      for (int k = 0; k < 3; ++k) palm_rot[h][k] += std::abs(v[k]) * 180 / units::kPi;
      palm_roll_deg[h].push_back(v.y() * 180 / units::kPi);
      palm_n[h] += 1;
      for (int k = hand::kThumbCmcFlexion; k < hand::kParamCount; ++k)
        param_err[h][static_cast<std::size_t>(k)].push_back(r.hands[h][k] - truth[h][k]);
    }
    // The joint error by part (the wrist, then each digit's four joints), and its floor: the
    // model's skeleton with the user's true sizes at the true pose, whose little finger can only
    // follow the ring finger's (the model has no parameters of its own for it).
    for (int h = 0; h < 2; ++h) {
      const auto fit_pts = hand::forward_kinematics(r.models[h], r.hands[h]);
      const auto true_pts = hand::forward_kinematics(truth_models[h], truth[h]);
      hand::HandParams coupled = truth[h];
      coupled.little_independent = false;
      const auto floor_pts = hand::forward_kinematics(truth_models[h], coupled);
      for (int j = 0; j < hand::kJointCount; ++j) {
        const Vec3& pt = true_pts.p_W_joint[static_cast<std::size_t>(j)];
        if (!(camera.depth(pt) > 0)) continue;
        const int part = j == 0 ? 0 : 1 + (j - 1) / 4;
        const Vec2 at = camera.project(pt);
        joint_part_sum[static_cast<std::size_t>(part)] +=
            (camera.project(fit_pts.p_W_joint[static_cast<std::size_t>(j)]) - at).norm();
        joint_floor_sum[static_cast<std::size_t>(part)] +=
            (camera.project(floor_pts.p_W_joint[static_cast<std::size_t>(j)]) - at).norm();
        joint_part_n[static_cast<std::size_t>(part)] += 1;
        // By joint along each digit (0 its base: the thumb's CMC, a finger's MCP; 3 its tip).
        if (j > 0) {
          const auto d = static_cast<std::size_t>((j - 1) / 4), k = static_cast<std::size_t>((j - 1) % 4);
          joint_at_sum[d][k] += (camera.project(fit_pts.p_W_joint[static_cast<std::size_t>(j)]) - at).norm();
          joint_at_floor[d][k] += (camera.project(floor_pts.p_W_joint[static_cast<std::size_t>(j)]) - at).norm();
          joint_at_n[d][k] += 1;
        }
      }
    }
    for (int h = 0; h < 2; ++h) iterations[h] += r.fits[static_cast<std::size_t>(h)].iterations;
    kept_restarts += r.restarts, kept_switches += r.depth_switches, kept_reaches += r.reaches;
    obs.push_back(1e3 * obs_res);
    caps.push_back(1e3 * cap_res);
    iou.push_back(m.iou);
    frame_t.push_back(t);
    tip.push_back(0.5 * (m.fingertip_mm[0] + m.fingertip_mm[1]));
    for (int h = 0; h < 2; ++h) {
      const registration::TermCosts& tc = r.fits[static_cast<std::size_t>(h)].terms;
      evidence_terms[0].push_back(tc.evidence());
      evidence_terms[1].push_back(tc.fingertip);
      evidence_terms[2].push_back(tc.wrist);
      evidence_terms[3].push_back(tc.joint_ball);
      evidence_terms[4].push_back(tc.silhouette);
    }
    joint.push_back(0.5 * (m.joint_px[0] + m.joint_px[1]));
    ceil_iou.push_back(c);
    if (m.contested_pixels > 0) {
      contested.push_back(m.contested_pct());
      contested_paper.push_back(m.contested_pct_paper());
    }
    if (a.verbose)
      std::printf("t %5.2f IoU %.3f (ceiling %.3f) tip %.2f/%.2f mm joints %.1f/%.1f px  bracelets %c%c  L %.4f/%.4f W %.4f/%.4f  wrist %.1f/%.1f sil %.1f/%.1f  depth %+.0f/%+.0f mm\n",
                  t, m.iou, c, m.fingertip_mm[0], m.fingertip_mm[1], m.joint_px[0], m.joint_px[1],
                  r.bracelets[0].found ? 'L' : '-', r.bracelets[1].found ? 'R' : '-',
                  r.models[0].shape.dimensions.length,
                  r.models[1].shape.dimensions.length, r.models[0].shape.dimensions.width,
                  r.models[1].shape.dimensions.width, r.fits[0].terms.wrist, r.fits[1].terms.wrist,
                  r.fits[0].terms.silhouette, r.fits[1].terms.silhouette, wrist_depth_mm[0].back(),
                  wrist_depth_mm[1].back());
  }
  std::printf(
      "frames %zu  IoU mean %.3f p5 %.3f  ceiling %.3f (p5 %.3f)  tip %.2f mm (p95 %.2f)  joints "
      "%.2f px  contested %.2f %% (paper %.2f %%)\n",
      iou.size(), mean(iou), quantile(iou, 0.05), mean(ceil_iou), quantile(ceil_iou, 0.05),
      mean(tip), quantile(tip, 0.95), mean(joint), mean(contested), mean(contested_paper));
  // What the fit costs, without a clock: its linear solves per frame, per hand, and how often a
  // second start was kept (a restart, the wrist's other depth, a digit re-posed to its string).
  std::printf("iterations per frame: left %.1f right %.1f; kept restarts %d, other depths %d, reaches %d\n",
              iou.empty() ? 0.0 : iterations[0] / static_cast<double>(iou.size()),
              iou.empty() ? 0.0 : iterations[1] / static_cast<double>(iou.size()), kept_restarts, kept_switches,
              kept_reaches);
  // The same figures second by second of the script: where in the run the fit loses (the approach,
  // the sizes' convergence, the release), each against its ceiling.
  {
    std::printf("by second of the script: IoU (ceiling) joints\n ");
    const int seconds = frame_t.empty() ? 0 : static_cast<int>(frame_t.back()) + 1;
    for (int b = 0; b < seconds; ++b) {
      std::vector<double> bi, bc, bj;
      for (std::size_t k = 0; k < frame_t.size(); ++k)
        if (static_cast<int>(frame_t[k]) == b) bi.push_back(iou[k]), bc.push_back(ceil_iou[k]), bj.push_back(joint[k]);
      if (!bi.empty()) std::printf(" %d: %.3f (%.3f) %.1f", b, mean(bi), mean(bc), mean(bj));
    }
    std::printf("\n");
  }
  {
    const hand::HandDimensions &l = r.models[0].shape.dimensions, &rt = r.models[1].shape.dimensions,
                               &tr = truth_models[0].shape.dimensions;
    std::printf("final model: L %.4f/%.4f W %.4f/%.4f cap y,z [mm] %.2f,%.2f / %.2f,%.2f (truth L %.4f W %.4f cap %.2f,%.2f)\n",
                l.length, rt.length, l.width, rt.width, 1e3 * l.fingertip_offset.y(), 1e3 * l.fingertip_offset.z(),
                1e3 * rt.fingertip_offset.y(), 1e3 * rt.fingertip_offset.z(), tr.length, tr.width,
                1e3 * tr.fingertip_offset.y(), 1e3 * tr.fingertip_offset.z());
  }
  std::printf("fit evidence per hand-frame %.3f (median %.3f): fingertip %.3f wrist %.3f joint-ball %.3f silhouette %.3f\n",
              mean(evidence_terms[0]), quantile(evidence_terms[0], 0.5), mean(evidence_terms[1]),
              mean(evidence_terms[2]), mean(evidence_terms[3]), mean(evidence_terms[4]));
  if (!variants.empty()) std::printf("ceiling as the model's skin: %.3f (p5 %.3f)\n", mean(ceil_iou), quantile(ceil_iou, 0.05));
  for (const Variant& v : variants)
    std::printf("ceiling with %s: %.3f (p5 %.3f)\n", v.name.c_str(), mean(v.iou), quantile(v.iou, 0.05));
  if (part_real > 0) {
    const char* names[7] = {"thumb", "index", "middle", "ring", "little", "palm", "wrist"};
    std::printf("ceiling's loss by nearest model part, %% of the real hand pixels: missing / extra\n");
    for (int k = 0; k < 7; ++k)
      std::printf("  %-7s %5.1f / %5.1f\n", names[k], 100 * part_missing[static_cast<std::size_t>(k)] / part_real,
                  100 * part_extra[static_cast<std::size_t>(k)] / part_real);
  }
  if (part_real > 0)
    std::printf("  (wrist: %.1f %% under the model's forearm or bracelet, the rest not covered)\n",
                100 * missing_under_forearm / part_real);
  {
    const char* names[6] = {"wrist", "thumb", "index", "middle", "ring", "little"};
    double fit_all = 0, floor_all = 0, n_all = 0;
    std::printf("joint error by part [px], fit / floor (true pose and sizes, the little finger following the ring):\n");
    for (std::size_t k = 0; k < 6; ++k) {
      const double n = std::max(joint_part_n[k], 1.0);
      std::printf("  %-7s %5.2f / %5.2f\n", names[k], joint_part_sum[k] / n, joint_floor_sum[k] / n);
      fit_all += joint_part_sum[k];
      floor_all += joint_floor_sum[k];
      n_all += joint_part_n[k];
    }
    const double little_n = std::max(joint_part_n[5], 1.0);
    std::printf("  all     %5.2f / %5.2f; without the little finger's error %.2f px\n", fit_all / std::max(n_all, 1.0),
                floor_all / std::max(n_all, 1.0),
                (fit_all - joint_part_sum[5] + joint_part_n[5] * (joint_part_sum[5] / little_n - joint_floor_sum[5] / little_n)) /
                    std::max(n_all, 1.0));
  }
  {
    const char* names[5] = {"thumb", "index", "middle", "ring", "little"};
    std::printf("joint error along each digit [px], base (CMC / MCP) to tip, fit (floor):\n");
    for (std::size_t d = 0; d < 5; ++d) {
      std::printf("  %-7s", names[d]);
      for (std::size_t k = 0; k < 4; ++k) {
        const double n = std::max(joint_at_n[d][k], 1.0);
        std::printf(" %5.2f (%5.2f)", joint_at_sum[d][k] / n, joint_at_floor[d][k] / n);
      }
      std::printf("\n");
    }
  }
  for (int h = 0; h < 2; ++h) {
    const auto& d = wrist_depth_mm[h];
    std::vector<double> magnitude(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) magnitude[i] = std::abs(d[i]);
    std::printf("%s wrist depth, fit − truth [mm]: median %+.1f (p10 %+.1f, p90 %+.1f), |·| mean %.1f\n",
                h == 0 ? "left" : "right", quantile(d, 0.5), quantile(d, 0.1), quantile(d, 0.9), mean(magnitude));
  }
  for (int h = 0; h < 2; ++h)
    std::printf("%s palm rotation error, mean |angle| about x_H (across) %.2f°, y_H (along) %.2f°, z_H (normal) %.2f°\n", h == 0 ? "left" : "right",
                palm_rot[h].x() / std::max(palm_n[h], 1.0), palm_rot[h].y() / std::max(palm_n[h], 1.0), palm_rot[h].z() / std::max(palm_n[h], 1.0));
  for (int h = 0; h < 2; ++h)
    std::printf("%s palm roll about y_H, signed [°]: p10 %+.1f, median %+.1f, p90 %+.1f\n", h == 0 ? "left" : "right",
                quantile(palm_roll_deg[h], 0.1), quantile(palm_roll_deg[h], 0.5), quantile(palm_roll_deg[h], 0.9));
  std::printf("finger parameters, fit − truth [°]: mean (mean |·|), correlation with the palm's roll\n");
  for (int k = hand::kThumbCmcFlexion; k < hand::kParamCount; ++k) {
    std::printf("  %-22s", std::string(hand::param_name(k)).c_str());
    for (int h = 0; h < 2; ++h) {
      const auto& e = param_err[h][static_cast<std::size_t>(k)];
      const auto& roll = palm_roll_deg[h];
      std::vector<double> magnitude(e.size());
      for (std::size_t i = 0; i < e.size(); ++i) magnitude[i] = std::abs(e[i]);
      const double me = mean(e), mr = mean(roll);
      double sxy = 0, sxx = 0, syy = 0;
      for (std::size_t i = 0; i < e.size() && i < roll.size(); ++i) {
        sxy += (e[i] - me) * (roll[i] - mr);
        sxx += (e[i] - me) * (e[i] - me);
        syy += (roll[i] - mr) * (roll[i] - mr);
      }
      const double corr = sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
      std::printf("  %s %+6.1f (%5.1f) r %+.2f", h == 0 ? "left" : "right", me * 180 / units::kPi,
                  mean(magnitude) * 180 / units::kPi, corr);
    }
    std::printf("\n");
  }
  std::printf("fitted caps to the strings %.2f mm (p95 %.2f), truth caps to the strings %.2f mm (max %.2f)\n",
              mean(obs), quantile(obs, 0.95), mean(caps), quantile(caps, 1.0));
  std::printf("bracelet midpoint to the band's axis centre %.2f px (p95 %.2f), to its visible surface %.2f px (p95 %.2f)\n",
              mean(brace_axis), quantile(brace_axis, 0.95), mean(brace_surf), quantile(brace_surf, 0.95));
  for (int k = 0; k < 6; ++k) std::printf("  shift %.1f r: %.2f px\n", 0.2 * k, brace_k[k] / std::max(brace_n, 1));
  std::printf("  the wrist term's point at the true pose: %.2f px (p95 %.2f)\n", mean(brace_term),
              quantile(brace_term, 0.95));
  std::printf("  the detector's midpoint predicted from the true band: %.2f px (p95 %.2f) on %zu of %zu frames "
              "(the wrist term's point on the same frames: %.2f px)\n",
              mean(brace_pred), quantile(brace_pred, 0.95), brace_pred.size(), brace_term.size(),
              mean(brace_term_where_pred));
  if (!chord_ratio.empty()) {
    std::sort(chord_ratio.begin(), chord_ratio.end());
    auto q = [&](double f) { return chord_ratio[static_cast<std::size_t>(f * static_cast<double>(chord_ratio.size() - 1))]; };
    std::printf("palm chord at the truth, real / model: median %.3f (p10 %.3f, p90 %.3f), %zu chords\n", q(0.5),
                q(0.1), q(0.9), chord_ratio.size());
  }
  if (a.section_widths) {
    const char* names[] = {"proximal", "middle", "distal", "all"};
    std::printf("digits' sections at the truth, real / model diameter: median (p10, p90), count\n");
    for (std::size_t k = 0; k < 4; ++k)
      if (!section_ratio[k].empty())
        std::printf("  %-9s %.3f (%.3f, %.3f) %zu\n", names[k], quantile(section_ratio[k], 0.5),
                    quantile(section_ratio[k], 0.1), quantile(section_ratio[k], 0.9), section_ratio[k].size());
  }
  std::printf("wrist depth switches %d, restarts %d\n", depth_switches, restarts);
  std::printf("forearm direction used − the simulated forearm's [°]: left median %.1f (p90 %.1f), right median %.1f (p90 %.1f)\n",
              quantile(forearm_err_deg[0], 0.5), quantile(forearm_err_deg[0], 0.9), quantile(forearm_err_deg[1], 0.5),
              quantile(forearm_err_deg[1], 0.9));
  if (oracle)
    std::printf("oracle: fits warm-started at the true pose each frame: IoU mean %.3f p5 %.3f, joints %.2f px "
                "(the objective's own minimum near the truth; tracked above)\n",
                mean(oracle_iou), quantile(oracle_iou, 0.05), mean(oracle_joint));
  if (oracle)
    for (int h = 0; h < 2; ++h) {
      std::printf("oracle %s: the fit from the truth explains the evidence better in %d of %d frames; "
                  "wrist depth |fit - truth| mean %.1f mm (tracked %.1f)\n",
                  h == 0 ? "left" : "right", oracle_better[h], oracle_n[h],
                  oracle_depth_sum[h] / std::max(oracle_n[h], 1), tracked_depth_sum[h] / std::max(oracle_n[h], 1));
      // Summed over windows of frames: would a tracker that compared hypotheses over time prefer it?
      std::printf("  summed over windows of");
      for (std::size_t w : {5u, 10u, 20u}) {
        int better = 0, n = 0;
        for (std::size_t i = 0; i + w <= oracle_e_truth[h].size(); i += w, ++n) {
          double st = 0, so = 0;
          for (std::size_t k = i; k < i + w; ++k) st += oracle_e_tracked[h][k], so += oracle_e_truth[h][k];
          better += so < st;
        }
        std::printf(" %zu frames: %d of %d;", w, better, n);
      }
      std::printf("\n");
      const auto& c = oracle_term_diff_cheaper[h];
      const auto& e = oracle_term_diff_dearer[h];
      std::printf("  tracked − from the truth, summed [fingertip, wrist, joint-ball, silhouette]: where the "
                  "tracked fit is cheaper %+.1f %+.1f %+.1f %+.1f; elsewhere %+.1f %+.1f %+.1f %+.1f\n",
                  c[0], c[1], c[2], c[3], e[0], e[1], e[2], e[3]);
    }
  std::printf("final shape: left L %.4f W %.4f T %.3f, right L %.4f W %.4f T %.3f (truth L %.4f W %.4f T %.3f)\n",
              r.models[0].shape.dimensions.length, r.models[0].shape.dimensions.width,
              r.models[0].shape.dimensions.thickness, r.models[1].shape.dimensions.length,
              r.models[1].shape.dimensions.width, r.models[1].shape.dimensions.thickness,
              truth_models[0].shape.dimensions.length, truth_models[0].shape.dimensions.width,
              truth_models[0].shape.dimensions.thickness);
  for (int h = 0; h < 2; ++h) {
    const registration::ShapeEstimate& e = r.shapes[h];
    std::printf("  %s: %d keyframes (%d with a palm chord), %d solves, sigma L %.4f W %.4f m%s%s\n",
                h == 0 ? "left" : "right", e.keyframes, e.palm_chords, e.solves, e.sigma_length_m, e.sigma_width_m,
                e.length_frozen ? ", length frozen" : "",
                e.width_frozen ? ", width frozen" : "");
  }
  return 0;
}
