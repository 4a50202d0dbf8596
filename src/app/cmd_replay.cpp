// spidar-mr replay DIR: re-runs registration and compositing offline on a recording made by
// `run --record DIR` (docs/recording.md), and writes report.json, a video and plots. Without
// ground truth the metrics are what a live session can measure: IoU of the fitted hands against
// the chroma-key silhouette, the registration's residual terms and iterations; and how closely
// the replay reproduces the recorded fits. The recording is read and checked by
// session::read_recording (a damaged or incomplete one is refused, exit 2, naming file:line:column).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "cli_support.hpp"
#include "commands.hpp"
#include "live_config.hpp"
#include "live_session.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/render/plot.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/recording_reader.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/capture.hpp"

namespace spidar::app {
namespace {

namespace fs = std::filesystem;

/// A statistic that needs data: the value, or null when there was nothing to compute it from
/// (a report never shows a perfect 0 for a comparison that did not happen).
nlohmann::json measured_or_null(double value, int samples) {
  return samples > 0 ? nlohmann::json(value) : nlohmann::json(nullptr);
}

}  // namespace

/// Replays a recording; returns the report (also written to out/report.json).
nlohmann::json replay_recording(const std::string& dir, const std::string& out, bool video_out) {
  const fs::path d(dir);
  const session::Recording rec = session::read_recording(dir);
  const std::string meta_file = (d / "session.json").string();
  const LiveConfig cfg = load_live_config(rec.config_path, false);
  if (rec.meta.width != cfg.width || rec.meta.height != cfg.height)
    throw UsageError(meta_file + ": size " + std::to_string(rec.meta.width) + "x" + std::to_string(rec.meta.height) +
                     " differs from config.yaml's " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height));
  const std::array<Vec3, 2> r0 = rec.meta.initial_r_W_hand;
  const bool png = rec.meta.store == session::FrameStore::kPng;
  const std::string codec = rec.meta.frames_codec;
  if (rec.frames.empty()) throw UsageError((d / "frames.csv").string() + ": no frames recorded");

  auto ctx_r = render::Context::create_headless();
  if (!ctx_r) throw SpidarError("OpenGL: " + ctx_r.error().message);
  auto context = std::move(ctx_r).value();
  const vision::Camera camera =
      session::scaled_camera(vision::load_camera_file(cfg.camera_calibration).camera, cfg.width, cfg.height);
  const auto models = session::hand_models(cfg.hands_file, cfg.model_profile, false);
  auto pipe_r = pipeline::FramePipeline::create(*context, camera, models, live_pipeline_params(cfg, r0));
  if (!pipe_r) throw UsageError(pipe_r.error().message);
  auto pipe = std::move(pipe_r).value();

  // The scene's structure from its MJCF, its poses per frame from scene.csv.
  physics::WorldParams wp;
  auto world_r = physics::World::Load(cfg.scene, wp);
  if (!world_r) throw UsageError(cfg.scene + ": " + world_r.error().message);
  SceneSnapshot scene;
  (*world_r)->snapshot(scene, false);
  if (!rec.scene.front().empty() && rec.scene.front().size() != scene.shapes.size())
    throw UsageError((d / "scene.csv").string() + ": " + std::to_string(rec.scene.front().size()) +
                     " shapes per frame, the scene has " + std::to_string(scene.shapes.size()) + " (" + cfg.scene +
                     ": was it changed since the recording?)");
  // Servo samples newest first, for re-interpolation at each exposure.
  const std::vector<device::FingertipSample> samples(rec.fingertips.rbegin(), rec.fingertips.rend());
  std::optional<vision::Capture> video_in;
  if (!png) {
    auto cap = vision::Capture::open(rec.video_path);
    if (!cap) throw UsageError("replay " + dir + ": " + cap.error().message);
    video_in = std::move(cap).value();
  }

  fs::create_directories(out);
  std::unique_ptr<render::VideoOutput> video;
  if (video_out) {
    auto v = render::VideoOutput::open((fs::path(out) / "replay.mp4").string(), cfg.width, cfg.height, cfg.fps);
    if (!v) throw SpidarError(v.error().message);
    video = std::move(v).value();
  }

  pipeline::FrameResult result;
  cv::Mat scratch;
  std::vector<double> t, iou, iters, ms;
  std::array<std::vector<double>, 5> terms;
  double max_dq = 0, max_dcost = 0, max_resample_mm = 0, sum_dq = 0;
  int compared = 0, compared_hands = 0, broken_fits = 0, resampled = 0, decode_errors = 0;
  const std::int64_t t0 = rec.frames.front().t_exposure_ns;
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    const session::FrameRow& f = rec.frames[i];
    // A frame that does not decode is counted and skipped (the next one is fitted from the last
    // decoded frame's fit, as the live loop does after a dropped frame).
    cv::Mat bgr;
    if (png) {
      bgr = cv::imread((d / f.image).string(), cv::IMREAD_COLOR);
    } else if (auto fr = video_in->read()) {
      bgr = fr->image;
    }
    if (bgr.empty() || bgr.cols != cfg.width || bgr.rows != cfg.height) {
      ++decode_errors;
      continue;
    }
    if (!rec.scene[i].empty())
      for (std::size_t k = 0; k < scene.shapes.size(); ++k) scene.shapes[k].X_WS = rec.scene[i][k];
    if (auto st = pipe->process(bgr, f.measured, scene, &result); !st) throw SpidarError(st.error().message);
    t.push_back(core::ns_to_s(f.t_exposure_ns - t0));
    iou.push_back(silhouette_iou(result, &scratch));
    iters.push_back(result.fits[0].iterations + result.fits[1].iterations);
    ms.push_back(result.timings.registration_ms);
    const auto& a = result.fits[0].terms;
    const auto& b = result.fits[1].terms;
    terms[0].push_back(a.fingertip + b.fingertip);
    terms[1].push_back(a.wrist + b.wrist);
    terms[2].push_back(a.joint_ball + b.joint_ball);
    terms[3].push_back(a.silhouette + b.silhouette);
    terms[4].push_back(a.prior + b.prior);
    ++compared;
    for (int h = 0; h < 2; ++h) {
      const session::FitRow& fit = rec.fits[i][static_cast<std::size_t>(h)];
      if (!fit.finite) {
        ++broken_fits;
        continue;
      }
      const hand::ParamVec q = Eigen::Map<const hand::ParamVec>(fit.q.data());
      const double dq = (result.hands[h].q - q).cwiseAbs().maxCoeff();
      max_dq = std::max(max_dq, finite_or(dq, 0.0));
      sum_dq += finite_or(dq, 0.0);
      ++compared_hands;
      max_dcost = std::max(max_dcost, finite_or(std::abs(result.fits[h].cost_final - fit.cost_final), 0.0));
    }
    if (auto s = device::interpolate_samples(samples, f.t_exposure_ns)) {
      ++resampled;
      for (int k = 0; k < s->finger_count; ++k)
        for (int c = 0; c < 3; ++c)
          max_resample_mm = std::max(max_resample_mm, std::abs(s->p_W[k][c] - f.measured.p_W[k][c]) * 1e3);
    }
    if (video) {
      if (auto st = video->write(result.composite); !st) throw SpidarError(st.error().message);
    }
  }
  if (t.empty())
    throw UsageError("replay " + dir + ": none of the " + std::to_string(rec.frames.size()) + " recorded frames decoded (" +
                     (png ? std::string("frames/*.png") : rec.video_path) + " damaged?)");
  if (video) video->close();

  auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  };
  std::vector<double> sorted = iou;
  std::sort(sorted.begin(), sorted.end());
  nlohmann::json j;
  j["recording"] = fs::absolute(d).string();
  j["frames"] = rec.frames.size();
  j["frames_replayed"] = t.size();
  j["decode_errors"] = decode_errors;
  j["recorded"] = {{"device_cycles", rec.device_rows},
                   {"fingertip_samples", rec.fingertips.size()},
                   {"seconds", rec.rows.seconds}};
  j["seconds"] = t.empty() ? 0.0 : t.back();
  j["registration"] = {{"iou_vs_silhouette_mean", mean(iou)},
                       {"iou_vs_silhouette_p5", sorted[sorted.size() / 20]},
                       {"iterations_mean", mean(iters)},
                       {"ms_mean", mean(ms)},
                       {"residual_mean", {{"fingertip", mean(terms[0])}, {"wrist", mean(terms[1])},
                                          {"joint_ball", mean(terms[2])}, {"silhouette", mean(terms[3])},
                                          {"prior", mean(terms[4])}}}};
  // Comparisons with no data are null, not a perfect 0.
  j["reproduction"] = {{"frames_compared", compared},
                       {"hands_compared", compared_hands},
                       {"max_param_diff", measured_or_null(max_dq, compared_hands)},
                       {"mean_param_diff", measured_or_null(compared_hands > 0 ? sum_dq / compared_hands : 0.0, compared_hands)},
                       {"recorded_fits_not_finite", broken_fits},
                       {"max_cost_diff", measured_or_null(max_dcost, compared_hands)},
                       {"fingertip_resample_frames", resampled},
                       {"fingertip_resample_max_mm", measured_or_null(max_resample_mm, resampled)},
                       {"frames_store", png ? "png (lossless)"
                                        : codec + " (lossy: the fits differ from the live ones)"}};
  j["outputs"] = {{"video", video ? video->path() : ""}};

  // Plots.
  auto write_plot = [&](const std::string& name, render::PlotSpec spec, std::vector<render::PlotSeries> s) {
    auto img = render::plot_lines(spec, s);
    if (!img) throw SpidarError(name + ": " + img.error().message);
    if (auto st = render::write_png((fs::path(out) / name).string(), *img); !st) throw SpidarError(st.error().message);
    j["outputs"]["plots"].push_back(name);
  };
  write_plot("iou.png", {"Fitted hands vs chroma-key silhouette", "time [s]", "IoU", 960, 360, 0.0, 1.0, {}},
             {{"IoU", t, iou, render::plot_colour(0)}});
  {
    std::vector<render::PlotSeries> s;
    const char* names[] = {"fingertip", "wrist", "joint-ball", "silhouette", "prior"};
    for (int k = 0; k < 5; ++k) s.push_back({names[k], t, terms[k], render::plot_colour(k)});
    write_plot("residuals.png", {"Registration residuals (both hands, final cost per term)", "time [s]", "cost", 960, 360, std::nullopt, std::nullopt, {}}, s);
  }
  write_plot("iterations.png", {"Registration iterations (both hands)", "time [s]", "iterations", 960, 360, 0.0, std::nullopt, {}},
             {{"iterations", t, iters, render::plot_colour(2)}});
  const std::string report = (fs::path(out) / "report.json").string();
  require_finite_json(j, report);
  core::write_file_atomic(report, j.dump(2) + "\n");
  return j;
}

Action add_replay(CLI::App& app) {
  auto* cmd = app.add_subcommand("replay",
                                 "Re-run registration and compositing on a recording (run --record); "
                                 "writes report.json, replay.mp4 and plots");
  struct Args {
    std::string dir, out;
    bool video = true;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("dir", a->dir, "recording folder")->required();
  cmd->add_option("--out", a->out, "output folder (default: DIR/replay)");
  cmd->add_flag("!--no-video", a->video, "do not write replay.mp4");
  return [a] {
    const std::string out = a->out.empty() ? (fs::path(a->dir) / "replay").string() : a->out;
    const auto j = replay_recording(a->dir, out, a->video);
    std::cout << j.dump(2) << "\n";
    return 0;
  };
}

}  // namespace spidar::app
