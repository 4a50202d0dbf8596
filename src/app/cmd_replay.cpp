// spidar-mr replay DIR: re-runs registration and compositing offline on a recording made by
// `run --record DIR` (docs/recording.md), and writes report.json, a video and plots. Without
// ground truth the metrics are what a live session can measure: IoU of the fitted hands against
// the chroma-key silhouette, the registration's residual terms and iterations; and how closely
// the replay reproduces the recorded fits.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "live_config.hpp"
#include "live_session.hpp"
#include "spidar/session/rig_inputs.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/physics/world.hpp"
#include "spidar/render/plot.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/capture.hpp"

namespace spidar::app {
namespace {

namespace fs = std::filesystem;

/// A CSV file with a header row: rows of fields, errors naming file:line.
class Csv {
 public:
  explicit Csv(const fs::path& path) : path_(path.string()), in_(path) {
    if (!in_) throw UsageError(path_ + ": cannot open (is this a recording folder? docs/recording.md)");
    std::string header;
    if (!std::getline(in_, header)) throw UsageError(path_ + ": empty (expected a header row)");
    columns_ = split(header).size();
    line_ = 1;
  }
  bool next() {
    std::string s;
    if (!std::getline(in_, s) || s.empty()) return false;
    ++line_;
    fields_ = split(s);
    if (fields_.size() != columns_)
      fail("expected " + std::to_string(columns_) + " fields, got " + std::to_string(fields_.size()));
    return true;
  }
  double d(std::size_t i) const {
    char* end = nullptr;
    const double v = std::strtod(fields_[i].c_str(), &end);
    if (end == fields_[i].c_str() || *end != '\0') fail("field " + std::to_string(i + 1) + ": expected a number, got '" + fields_[i] + "'");
    return v;
  }
  std::int64_t i64(std::size_t i) const {
    char* end = nullptr;
    const long long v = std::strtoll(fields_[i].c_str(), &end, 10);
    if (end == fields_[i].c_str() || *end != '\0') fail("field " + std::to_string(i + 1) + ": expected an integer, got '" + fields_[i] + "'");
    return v;
  }
  const std::string& s(std::size_t i) const { return fields_[i]; }
  std::size_t columns() const { return columns_; }
  [[noreturn]] void fail(const std::string& what) const {
    throw UsageError(path_ + ":" + std::to_string(line_) + ": " + what);
  }

 private:
  static std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    std::string f;
    while (std::getline(ss, f, ',')) out.push_back(f);
    if (!s.empty() && s.back() == ',') out.emplace_back();
    return out;
  }
  std::string path_;
  std::ifstream in_;
  std::size_t columns_ = 0;
  std::size_t line_ = 0;
  std::vector<std::string> fields_;
};

/// Reads the sample columns written by SessionRecorder starting at field `k`.
device::FingertipSample read_sample(const Csv& c, std::size_t k, std::int64_t t_ns) {
  device::FingertipSample s;
  s.t_ns = t_ns;
  s.faults = static_cast<std::uint32_t>(c.i64(k));
  s.consistent = static_cast<std::uint32_t>(c.i64(k + 1));
  s.finger_count = static_cast<int>(c.i64(k + 2));
  if (s.finger_count < 0 || s.finger_count > device::kMaxFingers) c.fail("finger_count out of range");
  std::size_t i = k + 3;
  for (auto& p : s.p_W)
    for (double& v : p) v = c.d(i++);
  for (auto& f : s.f_W)
    for (double& v : f) v = c.d(i++);
  return s;
}

struct RecordedFrame {
  std::int64_t index = 0, t_ns = 0;
  std::string image;
  device::FingertipSample measured;
};

struct RecordedFit {
  std::array<hand::HandParams, 2> hands;
  std::array<double, 2> cost{};
  /// The row had a NaN or infinity (a live fit that diverged): not compared.
  std::array<bool, 2> broken{};
};

}  // namespace

/// Replays a recording; returns the report (also written to out/report.json).
nlohmann::json replay_recording(const std::string& dir, const std::string& out, bool video_out) {
  const fs::path d(dir);
  if (!fs::is_regular_file(d / "session.json"))
    throw UsageError("replay " + dir + ": no session.json (expected a folder written by run --record)");
  nlohmann::json meta;
  try {
    std::ifstream f(d / "session.json");
    meta = nlohmann::json::parse(f);
  } catch (const std::exception& e) {
    throw UsageError((d / "session.json").string() + ": not valid JSON: " + e.what());
  }
  const std::string meta_file = (d / "session.json").string();
  const LiveConfig cfg = load_live_config((d / "config.yaml").string(), false);
  std::array<Vec3, 2> r0;
  bool png = false;
  std::string codec;
  try {
    if (meta.value("format", "") != "spidar-mr recording" || meta.value("version", 0) != 1)
      throw UsageError(meta_file + ": expected format 'spidar-mr recording' version 1");
    const int width = meta.at("width"), height = meta.at("height");
    if (width != cfg.width || height != cfg.height) throw UsageError(meta_file + ": size differs from config.yaml");
    for (int h = 0; h < 2; ++h) {
      const auto& v = meta.at("initial_r_W_hand").at(h);
      r0[h] = Vec3(v.at(0).get<double>(), v.at(1).get<double>(), v.at(2).get<double>());
    }
    png = meta.value("frames", "video") == "png";
    codec = meta.value("frames_codec", "mp4");
  } catch (const nlohmann::json::exception& e) {
    throw UsageError(meta_file + ": " + e.what() + " (docs/recording.md lists its keys)");
  }

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
  std::map<std::int64_t, std::vector<Pose>> poses;
  {
    Csv c(d / "scene.csv");
    while (c.next()) {
      const std::int64_t shape = c.i64(1);
      if (shape < 0 || shape >= static_cast<std::int64_t>(scene.shapes.size()))
        c.fail("shape " + std::to_string(shape) + " not in the scene (" + std::to_string(scene.shapes.size()) +
               " shapes in " + cfg.scene + ": was it changed since the recording?)");
      Pose X;
      X.p = Vec3(c.d(2), c.d(3), c.d(4));
      X.R = Eigen::Quaterniond(c.d(5), c.d(6), c.d(7), c.d(8));
      auto& v = poses[c.i64(0)];
      if (static_cast<std::int64_t>(v.size()) != shape) c.fail("shapes out of order");
      v.push_back(X);
    }
  }
  std::map<std::int64_t, RecordedFit> recorded;
  {
    Csv c(d / "fits.csv");
    while (c.next()) {
      const int h = static_cast<int>(c.i64(1));
      if (h < 0 || h > 1) c.fail("hand must be 0 or 1");
      RecordedFit& r = recorded[c.i64(0)];
      r.cost[h] = c.d(5);
      for (int i = 0; i < hand::kParamCount; ++i) r.hands[h].q[i] = c.d(11 + i);
      r.broken[h] = !std::isfinite(r.cost[h]) || !r.hands[h].q.allFinite();
    }
  }
  std::vector<device::FingertipSample> samples;  // newest first, for re-interpolation
  {
    Csv c(d / "fingertips.csv");
    while (c.next()) {
      auto s = read_sample(c, 2, c.i64(0));
      s.cycle = static_cast<std::uint64_t>(c.i64(1));
      samples.push_back(s);
    }
    std::reverse(samples.begin(), samples.end());
  }
  std::vector<RecordedFrame> frames;
  {
    Csv c(d / "frames.csv");
    while (c.next()) {
      RecordedFrame f;
      f.index = c.i64(0);
      f.t_ns = c.i64(1);
      f.image = c.s(2);
      f.measured = read_sample(c, 3, f.t_ns);
      frames.push_back(std::move(f));
    }
  }
  if (frames.empty()) throw UsageError((d / "frames.csv").string() + ": no frames recorded");
  std::optional<vision::Capture> video_in;
  if (!png) {
    auto cap = vision::Capture::open((d / "camera.mp4").string());
    if (!cap) {
      auto avi = vision::Capture::open((d / "camera.avi").string());
      if (!avi) throw UsageError("replay " + dir + ": " + cap.error().message);
      cap = std::move(avi);
    }
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
  int compared = 0, compared_hands = 0, broken_fits = 0;
  const std::int64_t t0 = frames.front().t_ns;
  for (const RecordedFrame& f : frames) {
    cv::Mat bgr;
    if (png) {
      bgr = cv::imread((d / f.image).string(), cv::IMREAD_COLOR);
      if (bgr.empty()) throw UsageError((d / f.image).string() + ": missing or not an image");
    } else {
      auto fr = video_in->read();
      if (!fr) throw UsageError("replay: camera video ends before frame " + std::to_string(f.index));
      bgr = fr->image;
    }
    if (auto it = poses.find(f.index); it != poses.end()) {
      if (it->second.size() != scene.shapes.size())
        throw UsageError((d / "scene.csv").string() + ": frame " + std::to_string(f.index) + " has " +
                         std::to_string(it->second.size()) + " shapes, the scene " + std::to_string(scene.shapes.size()));
      for (std::size_t i = 0; i < scene.shapes.size(); ++i) scene.shapes[i].X_WS = it->second[i];
    }
    if (auto st = pipe->process(bgr, f.measured, scene, &result); !st) throw SpidarError(st.error().message);
    t.push_back(core::ns_to_s(f.t_ns - t0));
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
    if (auto it = recorded.find(f.index); it != recorded.end()) {
      ++compared;
      for (int h = 0; h < 2; ++h) {
        if (it->second.broken[h]) {
          ++broken_fits;
          continue;
        }
        const double dq = (result.hands[h].q - it->second.hands[h].q).cwiseAbs().maxCoeff();
        max_dq = std::max(max_dq, finite_or(dq, 0.0));
        sum_dq += finite_or(dq, 0.0);
        ++compared_hands;
        max_dcost = std::max(max_dcost, finite_or(std::abs(result.fits[h].cost_final - it->second.cost[h]), 0.0));
      }
    }
    if (auto s = device::interpolate_samples(samples, f.t_ns)) {
      for (int k = 0; k < s->finger_count; ++k)
        for (int i = 0; i < 3; ++i)
          max_resample_mm = std::max(max_resample_mm, std::abs(s->p_W[k][i] - f.measured.p_W[k][i]) * 1e3);
    }
    if (video) {
      if (auto st = video->write(result.composite); !st) throw SpidarError(st.error().message);
    }
  }
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
  j["frames"] = frames.size();
  j["seconds"] = t.empty() ? 0.0 : t.back();
  j["registration"] = {{"iou_vs_silhouette_mean", mean(iou)},
                       {"iou_vs_silhouette_p5", sorted[sorted.size() / 20]},
                       {"iterations_mean", mean(iters)},
                       {"ms_mean", mean(ms)},
                       {"residual_mean", {{"fingertip", mean(terms[0])}, {"wrist", mean(terms[1])},
                                          {"joint_ball", mean(terms[2])}, {"silhouette", mean(terms[3])},
                                          {"prior", mean(terms[4])}}}};
  j["reproduction"] = {{"frames_compared", compared},
                       {"max_param_diff", max_dq},
                       {"mean_param_diff", compared_hands > 0 ? sum_dq / compared_hands : 0.0},
                       {"recorded_fits_not_finite", broken_fits},
                       {"max_cost_diff", max_dcost},
                       {"fingertip_resample_max_mm", max_resample_mm},
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
  require_finite_json(j, (fs::path(out) / "report.json").string());
  std::ofstream rep(fs::path(out) / "report.json");
  rep << j.dump(2) << "\n";
  if (!rep) throw SpidarError("cannot write " + (fs::path(out) / "report.json").string());
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
