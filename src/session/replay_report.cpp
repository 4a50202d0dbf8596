#include "spidar/session/replay_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "spidar/core/atomic_write.hpp"
#include "spidar/device/sample_interpolation.hpp"
#include "spidar/render/plot.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/finite_json.hpp"
#include "spidar/session/frame_stats.hpp"
#include "spidar/session/json_text.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;

/// `x` if finite, else 0 (a difference with a diverged fit does not count).
double finite_or_zero(double x) { return std::isfinite(x) ? x : 0.0; }

/// A statistic that needs data: the value, or null when there was nothing to compute it from
/// (a report never shows a perfect 0 for a comparison that did not happen).
nlohmann::json measured_or_null(double value, int samples) {
  return samples > 0 ? nlohmann::json(value) : nlohmann::json(nullptr);
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace

ReplayScorer::ReplayScorer(const RecordingRig& rig)
    : rig_(rig),
      newest_first_(rig.recording().fingertips.rbegin(), rig.recording().fingertips.rend()) {}

void ReplayScorer::on_frame(const FrameEvent& e) {
  const Recording& rec = rig_.recording();
  const std::size_t i = rig_.row();
  const pipeline::FrameResult& result = *e.result;
  f_.t.push_back(e.t_s);
  f_.iou.push_back(silhouette_iou(result, &scratch_));
  f_.iterations.push_back(result.fits[0].iterations + result.fits[1].iterations);
  f_.ms.push_back(result.timings.registration_ms);
  const auto& a = result.fits[0].terms;
  const auto& b = result.fits[1].terms;
  f_.terms[0].push_back(a.fingertip + b.fingertip);
  f_.terms[1].push_back(a.wrist + b.wrist);
  f_.terms[2].push_back(a.joint_ball + b.joint_ball);
  f_.terms[3].push_back(a.silhouette + b.silhouette);
  f_.terms[4].push_back(a.prior + b.prior);
  ++f_.compared;
  for (int h = 0; h < 2; ++h) {
    const FitRow& fit = rec.fits[i][static_cast<std::size_t>(h)];
    // The model's sizes are the fit's input: compared also where the live fit was not finite.
    const hand::HandDimensions& d = result.models[h].shape.dimensions;
    f_.final_size[h] = {d.length, d.width};
    f_.live_final_size[h] = {fit.length_m, fit.width_m};
    if (fit.length_m > 0) {  // recorded
      ++f_.compared_sizes;
      f_.max_dsize_mm = std::max({f_.max_dsize_mm, std::abs(d.length - fit.length_m) * 1e3,
                                  std::abs(d.width - fit.width_m) * 1e3});
    }
    if (!fit.finite) {
      ++f_.broken_fits;
      continue;
    }
    // The paper's 17 parameters (a recording does not store a little finger of its own).
    const auto q = Eigen::Map<const Eigen::Matrix<double, hand::kPaperParamCount, 1>>(fit.q.data());
    const double dq =
        finite_or_zero((result.hands[h].q.head<hand::kPaperParamCount>() - q).cwiseAbs().maxCoeff());
    f_.max_dq = std::max(f_.max_dq, dq);
    f_.sum_dq += dq;
    ++f_.compared_hands;
    f_.max_dcost = std::max(f_.max_dcost, finite_or_zero(std::abs(result.fits[h].cost_final - fit.cost_final)));
  }
  const device::FingertipSample& recorded = rec.frames[i].measured;
  if (auto s = device::interpolate_samples(newest_first_, e.t_exposure_ns)) {
    ++f_.resampled;
    for (int k = 0; k < s->finger_count; ++k)
      for (int c = 0; c < 3; ++c)
        f_.max_resample_mm = std::max(f_.max_resample_mm, std::abs(s->p_W[k][c] - recorded.p_W[k][c]) * 1e3);
  }
}

nlohmann::json write_replay_report(const std::string& out, const RecordingRig& rig,
                                   const ReplayScorer& scorer, const std::string& video) {
  const Recording& rec = rig.recording();
  const ReplayScorer::Figures& f = scorer.figures();
  const bool png = rec.meta.store == FrameStore::kPng;
  std::vector<double> sorted = f.iou;
  std::sort(sorted.begin(), sorted.end());
  nlohmann::json j;
  j["recording"] = fs::absolute(rec.dir).string();
  j["frames"] = rec.frames.size();
  j["frames_replayed"] = f.t.size();
  j["decode_errors"] = rig.decode_errors();
  if (!rig.first_decode_error().empty()) j["decode_error_first"] = rig.first_decode_error();
  j["recorded"] = {{"device_cycles", rec.device_rows},
                   {"fingertip_samples", rec.fingertips.size()},
                   {"seconds", rec.rows.seconds}};
  j["seconds"] = f.t.empty() ? 0.0 : f.t.back();
  j["registration"] = {{"iou_vs_silhouette_mean", mean(f.iou)},
                       {"iou_vs_silhouette_p5", sorted.empty() ? 0.0 : sorted[sorted.size() / 20]},
                       {"iterations_mean", mean(f.iterations)},
                       {"ms_mean", mean(f.ms)},
                       {"residual_mean", {{"fingertip", mean(f.terms[0])}, {"wrist", mean(f.terms[1])},
                                          {"joint_ball", mean(f.terms[2])}, {"silhouette", mean(f.terms[3])},
                                          {"prior", mean(f.terms[4])}}}};
  // Each hand's sizes after the last frame: the replay's (personalised when the config says so)
  // and, when the recording has them, the live run's.
  for (int h = 0; h < 2; ++h) {
    nlohmann::json side = {{"length_m", f.final_size[h][0]}, {"width_m", f.final_size[h][1]}};
    if (f.live_final_size[h][0] > 0)
      side["live"] = {{"length_m", f.live_final_size[h][0]}, {"width_m", f.live_final_size[h][1]}};
    j["registration"]["hand_shape"][h == 0 ? "left" : "right"] = side;
  }
  // Comparisons with no data are null here, not a perfect 0 ...
  const int hands = f.compared_hands;
  j["reproduction"] = {{"frames_compared", f.compared},
                       {"hands_compared", hands},
                       {"max_param_diff", measured_or_null(f.max_dq, hands)},
                       {"mean_param_diff", measured_or_null(hands > 0 ? f.sum_dq / hands : 0.0, hands)},
                       {"recorded_fits_not_finite", f.broken_fits},
                       {"max_cost_diff", measured_or_null(f.max_dcost, hands)},
                       {"max_hand_size_diff_mm", measured_or_null(f.max_dsize_mm, f.compared_sizes)},
                       {"fingertip_resample_frames", f.resampled},
                       {"fingertip_resample_max_mm", measured_or_null(f.max_resample_mm, f.resampled)},
                       {"frames_store", png ? "png (lossless)"
                                        : rec.meta.frames_codec + " (lossy: the fits differ from the live ones)"}};
  // ... and then not written at all: JSON we write holds no null (issue 17). Their names are listed
  // in reproduction.not_measured instead.
  nlohmann::json not_measured = nlohmann::json::array();
  for (const auto& [key, value] : j["reproduction"].items())
    if (value.is_null()) not_measured.push_back(key);
  for (const auto& key : not_measured) j["reproduction"].erase(key.get<std::string>());
  j["reproduction"]["not_measured"] = not_measured;
  j["outputs"] = {{"video", video}};

  auto write_plot = [&](const std::string& name, render::PlotSpec spec, std::vector<render::PlotSeries> s) {
    auto img = render::plot_lines(spec, s);
    if (!img) throw SpidarError(name + ": " + img.error().message);
    if (auto st = render::write_png((fs::path(out) / name).string(), *img); !st) throw SpidarError(st.error().message);
    j["outputs"]["plots"].push_back(name);
  };
  write_plot("iou.png", {"Fitted hands vs chroma-key silhouette", "time [s]", "IoU", 960, 360, 0.0, 1.0, {}},
             {{"IoU", f.t, f.iou, render::plot_colour(0)}});
  {
    std::vector<render::PlotSeries> s;
    const char* names[] = {"fingertip", "wrist", "joint-ball", "silhouette", "prior"};
    for (int k = 0; k < 5; ++k) s.push_back({names[k], f.t, f.terms[static_cast<std::size_t>(k)], render::plot_colour(k)});
    write_plot("residuals.png", {"Registration residuals (both hands, final cost per term)", "time [s]", "cost", 960, 360, std::nullopt, std::nullopt, {}}, s);
  }
  write_plot("iterations.png", {"Registration iterations (both hands)", "time [s]", "iterations", 960, 360, 0.0, std::nullopt, {}},
             {{"iterations", f.t, f.iterations, render::plot_colour(2)}});
  const std::string report = (fs::path(out) / "report.json").string();
  require_finite_json(j, report);
  core::write_file_atomic(report, json_text(j, 2) + "\n");
  return j;
}

}  // namespace spidar::session
