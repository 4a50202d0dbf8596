#include "spidar/session/run_report.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <iomanip>
#include <functional>
#include <nlohmann/json.hpp>

#include "spidar/core/atomic_write.hpp"
#include "spidar/device/device.hpp"
#include "spidar/render/plot.hpp"
#include "spidar/render/video_output.hpp"
#include "spidar/session/finite_json.hpp"
#include "spidar/session/stats_json.hpp"
#include "spidar/session/json_text.hpp"

namespace spidar::session {
namespace {

namespace fs = std::filesystem;

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}
/// `v` with `decimals` digits after the point.
std::string fixed_text(double v, int decimals) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(decimals) << v;
  return o.str();
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

template <typename F>
std::vector<double> column(const MrTrace& t, F f) {
  std::vector<double> v;
  v.reserve(t.frames.size());
  for (const auto& m : t.frames) v.push_back(f(m));
  return v;
}

/// The frames of `t` whose variant k (0 main, 1 comparison) had a real or fitted hand in view.
MrTrace in_view(const MrTrace& t, int k) {
  MrTrace out;
  for (const auto& m : t.frames)
    if (m.truth[k].scored_in_image()) out.frames.push_back(m);
  return out;
}

/// Registration figures of one variant (0 main, 1 comparison).
nlohmann::json registration_json(const MrTrace& all, int k) {
  MrTrace t;
  for (const auto& m : all.frames) {
    if (k == 0 || m.compared) t.frames.push_back(m);
  }
  // The image's figures over the frames where a real or fitted hand was in view (scored_in_image).
  const MrTrace seen = in_view(t, k);
  const auto iou = column(seen, [k](const MrFrame& m) { return m.truth[k].iou; });
  const auto jp = column(seen, [k](const MrFrame& m) { return 0.5 * (m.truth[k].joint_px[0] + m.truth[k].joint_px[1]); });
  const auto tip = column(t, [k](const MrFrame& m) { return 0.5 * (m.truth[k].fingertip_mm[0] + m.truth[k].fingertip_mm[1]); });
  const auto occ = column(t, [k](const MrFrame& m) { return m.truth[k].occlusion_pct; });
  std::vector<double> depth;  // both hands' wrists, |fit − truth| along the optical axis
  for (const MrFrame& m : t.frames)
    for (double d : m.truth[k].wrist_depth_mm) depth.push_back(std::abs(d));
  std::vector<double> wrist_px;  // both hands' wrists in the image, where both are in front
  for (const MrFrame& m : seen.frames)
    for (double d : m.truth[k].wrist_px)
      if (std::isfinite(d)) wrist_px.push_back(d);
  // How each fitted palm is turned against the true one [deg] (FrameTruthMetrics::palm_rotation_deg):
  // the angle, and the signed means of its three parts (a bias shows there).
  nlohmann::json palm;
  for (int h = 0; h < 2; ++h) {
    const auto part = [&](int c) {
      return mean(column(t, [k, h, c](const MrFrame& m) { return m.truth[k].palm_rotation_deg[h][c]; }));
    };
    const auto angle = column(t, [k, h](const MrFrame& m) { return m.truth[k].palm_rotation_deg[h].norm(); });
    palm[h == 0 ? "left" : "right"] = {{"angle_mean", mean(angle)},
                                       {"angle_p95", quantile(angle, 0.95)},
                                       {"pitch_mean", part(0)},
                                       {"roll_mean", part(1)},
                                       {"turn_mean", part(2)}};
  }
  return {{"iou_mean", mean(iou)},
          {"iou_p5", quantile(iou, 0.05)},
          {"palm_rotation_deg", palm},
          {"joint_px_mean", mean(jp)},
          {"wrist_depth_mm_mean", mean(depth)},
          {"wrist_px_mean", mean(wrist_px)},
          {"wrist_depth_mm_p95", quantile(depth, 0.95)},
          {"fingertip_mm_mean", mean(tip)},
          {"fingertip_mm_p95", quantile(tip, 0.95)},
          {"occlusion_error_pct", mean(occ)},
          {"frames", t.frames.size()},
          {"frames_scored_in_image", seen.frames.size()}};
}

/// The main registration's figures and the contested pixels over the frames of each part of the
/// task (`phases`: one word per trace frame), in the order the parts first occur: where the hard
/// frames are (the approach and the release, one hand or forearm hiding the other) without the
/// run's easy frames averaging them away. Empty without phases.
nlohmann::ordered_json by_phase_json(const MrTrace& t, const std::vector<std::string>& phases) {
  nlohmann::ordered_json out = nlohmann::ordered_json::object();
  if (phases.size() != t.frames.size()) return out;
  std::vector<std::string> order;
  for (const auto& p : phases)
    if (std::find(order.begin(), order.end(), p) == order.end()) order.push_back(p);
  for (const auto& name : order) {
    MrTrace part;
    long contested = 0, wrong = 0, wrong_paper = 0;
    for (std::size_t i = 0; i < t.frames.size(); ++i) {
      if (phases[i] != name) continue;
      const MrFrame& m = t.frames[i];
      part.frames.push_back(m);
      contested += m.truth[0].contested_pixels;
      wrong += m.truth[0].contested_wrong;
      wrong_paper += m.truth[0].contested_wrong_paper;
    }
    const MrTrace seen = in_view(part, 0);
    const auto iou = column(seen, [](const MrFrame& m) { return m.truth[0].iou; });
    const auto jp = column(seen, [](const MrFrame& m) { return 0.5 * (m.truth[0].joint_px[0] + m.truth[0].joint_px[1]); });
    const auto tip = column(part, [](const MrFrame& m) { return 0.5 * (m.truth[0].fingertip_mm[0] + m.truth[0].fingertip_mm[1]); });
    const auto pct = [contested](long w) { return contested > 0 ? 100.0 * static_cast<double>(w) / static_cast<double>(contested) : 0.0; };
    out[name] = {{"frames", part.frames.size()},
                 {"iou_mean", mean(iou)},
                 {"iou_p5", quantile(iou, 0.05)},
                 {"joint_px_mean", mean(jp)},
                 {"fingertip_mm_mean", mean(tip)},
                 {"contested_pixels_mean", static_cast<double>(contested) / static_cast<double>(part.frames.size())},
                 {"contested_error_pct", pct(wrong)},
                 {"contested_error_pct_paper", pct(wrong_paper)}};
  }
  return out;
}

/// The summary's line of by_phase_json: each part's IoU (p5) and contested pixels wrong; empty
/// without parts.
std::string by_phase_line(const nlohmann::ordered_json& by_phase) {
  if (by_phase.empty()) return {};
  std::ostringstream line;
  line << "  by phase       IoU (p5), contested wrong:";
  const char* sep = " ";
  for (const auto& [name, v] : by_phase.items()) {
    line << sep << name << " " << std::fixed << std::setprecision(3) << v["iou_mean"].get<double>() << " ("
         << std::setprecision(2) << v["iou_p5"].get<double>() << "), " << std::setprecision(1)
         << v["contested_error_pct"].get<double>() << " %";
    sep = "; ";
  }
  return line.str() + "\n";
}

/// A frames.csv cell: the number, or nothing where it is not defined (not finite: a hand out of
/// view, a wrist behind the camera), as the other missing values are written.
struct Cell {
  double v;
};
std::ostream& operator<<(std::ostream& o, Cell c) {
  if (std::isfinite(c.v)) o << c.v;
  return o;
}

/// One row per processed frame: what the report's figures are computed from.
void write_frames_csv(const std::string& path, const MrTrace& t, const std::vector<std::string>& phases) {
  std::ostringstream f;
  f << "t_s,latency_ms,pipeline_ms,registration_ms,truth_ms,output_ms,film_ms,iou,fingertip_mm,"
       "joint_px_left,joint_px_right,occlusion_pct,occlusion_pct_paper,contested_pixels,"
       "contested_error_pct,contested_error_pct_paper,iterations_left,"
       "iterations_right,compared,iou_comparison,lift_mm,u_angle_deg,turns,servo_rate_hz,"
       "servo_jitter_max_us,cap_residual_mm_left,cap_residual_mm_right,model_ceiling_iou,"
       "length_mm_left,width_mm_left,length_mm_right,width_mm_right,dropped_before,joint_px_floor,"
       "wrist_depth_mm_left,wrist_depth_mm_right,wrist_px_left,wrist_px_right,palm_angle_deg_left,palm_roll_deg_left,"
       "palm_angle_deg_right,palm_roll_deg_right,phase\n";
  f << std::setprecision(6);
  for (std::size_t i = 0; i < t.frames.size(); ++i) {
    const MrFrame& m = t.frames[i];
    const auto& a = m.truth[0];
    f << Cell{m.t_s} << ',' << Cell{m.latency_ms} << ',' << Cell{m.pipeline_ms} << ',' << Cell{m.registration_ms}
      << ',' << Cell{m.truth_ms} << ',' << Cell{m.output_ms} << ',' << Cell{m.film_ms} << ',' << Cell{a.iou} << ','
      << Cell{0.5 * (a.fingertip_mm[0] + a.fingertip_mm[1])} << ',' << Cell{a.joint_px[0]} << ','
      << Cell{a.joint_px[1]} << ',' << Cell{a.occlusion_pct} << ',' << Cell{a.occlusion_pct_paper} << ','
      << a.contested_pixels << ',' << Cell{a.contested_pct()} << ',' << Cell{a.contested_pct_paper()} << ','
      << m.iterations[0] << ',' << m.iterations[1] << ',' << (m.compared ? 1 : 0) << ',';
    if (m.compared) f << Cell{m.truth[1].iou};
    f << ',' << Cell{m.lift_mm} << ',' << Cell{m.u_angle_deg} << ',' << m.turns << ',' << Cell{m.servo_rate_hz} << ','
      << Cell{m.servo_jitter_max_us} << ',' << Cell{m.truth_cap_residual_mm[0]} << ','
      << Cell{m.truth_cap_residual_mm[1]} << ',';
    if (m.ceiling_measured) f << Cell{m.ceiling_iou};
    for (int h = 0; h < 2; ++h) f << ',' << Cell{1e3 * m.shape[h].length_m} << ',' << Cell{1e3 * m.shape[h].width_m};
    f << ',' << m.dropped_before << ',' << Cell{0.5 * (a.joint_px_floor[0] + a.joint_px_floor[1])} << ','
      << Cell{a.wrist_depth_mm[0]} << ',' << Cell{a.wrist_depth_mm[1]} << ',' << Cell{a.wrist_px[0]} << ','
      << Cell{a.wrist_px[1]} << ',' << Cell{a.palm_rotation_deg[0].norm()} << ',' << Cell{a.palm_rotation_deg[0].y()}
      << ',' << Cell{a.palm_rotation_deg[1].norm()} << ',' << Cell{a.palm_rotation_deg[1].y()}
      << ',' << (i < phases.size() ? phases[i] : "")
      << '\n';
  }
  core::write_file_atomic(path, f.str());
}

void save_plot(const std::string& path, const render::PlotSpec& spec,
               const std::vector<render::PlotSeries>& series) {
  auto img = render::plot_lines(spec, series);
  if (!img) throw SpidarError(img.error().message);
  if (auto st = render::write_png(path, *img); !st) throw SpidarError(st.error().message);
}

render::PlotSeries series(const MrTrace& t, const std::string& label, int colour,
                          const std::function<double(const MrFrame&)>& f) {
  render::PlotSeries s;
  s.label = label;
  s.bgr = render::plot_colour(colour);
  s.x = column(t, [](const MrFrame& m) { return m.t_s; });
  s.y = column(t, f);
  return s;
}

void write_plots(const fs::path& dir, const MrTrace& t, const MrSummary& summary) {
  using S = std::vector<render::PlotSeries>;
  {
    render::PlotSpec spec;
    spec.title = "Registration error vs ground truth (main registration)";
    spec.x_label = "time [s]";
    spec.y_label = "mm / px";
    spec.references = {{"target 2 mm", 2.0, render::plot_colour(7)}};
    save_plot((dir / "registration_error.png").string(), spec,
              S{series(t, "left fingertip [mm]", 0, [](const MrFrame& m) { return m.truth[0].fingertip_mm[0]; }),
                series(t, "right fingertip [mm]", 1, [](const MrFrame& m) { return m.truth[0].fingertip_mm[1]; }),
                series(t, "left joints [px]", 2, [](const MrFrame& m) { return m.truth[0].joint_px[0]; }),
                series(t, "right joints [px]", 3, [](const MrFrame& m) { return m.truth[0].joint_px[1]; })});
  }
  if (!t.frames.empty() && summary.user_length_m > 0) {
    // The registration's size estimates converging (personalisation) against the user's sizes.
    render::PlotSpec spec;
    spec.title = "Hand size: the registration's estimate and the user's true size";
    spec.x_label = "time [s]";
    spec.y_label = "mm";
    spec.references = {{"true length", 1e3 * summary.user_length_m, render::plot_colour(7)},
                       {"true width", 1e3 * summary.user_width_m, render::plot_colour(6)}};
    save_plot((dir / "hand_shape.png").string(), spec,
              S{series(t, "left length", 0, [](const MrFrame& m) { return 1e3 * m.shape[0].length_m; }),
                series(t, "right length", 1, [](const MrFrame& m) { return 1e3 * m.shape[1].length_m; }),
                series(t, "left width", 2, [](const MrFrame& m) { return 1e3 * m.shape[0].width_m; }),
                series(t, "right width", 3, [](const MrFrame& m) { return 1e3 * m.shape[1].width_m; })});
  }
  {
    render::PlotSpec spec;
    spec.title = "Silhouette IoU of the fitted hands (ground truth)";
    spec.x_label = "time [s]";
    spec.y_label = "IoU";
    spec.y_min = 0.0;
    spec.y_max = 1.0;
    spec.references = {{"target 0.93", 0.93, render::plot_colour(7)}};
    save_plot((dir / "iou.png").string(), spec,
              S{series(t, "IoU", 0, [](const MrFrame& m) { return m.truth[0].iou; })});
  }
  {
    render::PlotSpec spec;
    spec.title = "Occlusion error: hand region, and contested pixels (hand over an object)";
    spec.x_label = "time [s]";
    spec.y_label = "%";
    spec.references = {{"target 5 % (contested)", 5.0, render::plot_colour(7)}};
    // Contested curves only where a frame has contested pixels (elsewhere no compositor can err).
    MrTrace contested;
    for (const MrFrame& m : t.frames)
      if (m.truth[0].contested_pixels > 0) contested.frames.push_back(m);
    S curves{series(t, "depth, hand region", 2, [](const MrFrame& m) { return m.truth[0].occlusion_pct; }),
             series(t, "paper, hand region", 5, [](const MrFrame& m) { return m.truth[0].occlusion_pct_paper; })};
    if (contested.frames.size() > 1) {
      curves.push_back(series(contested, "depth, contested", 0, [](const MrFrame& m) { return m.truth[0].contested_pct(); }));
      curves.push_back(series(contested, "paper, contested", 1, [](const MrFrame& m) { return m.truth[0].contested_pct_paper(); }));
    }
    save_plot((dir / "occlusion.png").string(), spec, curves);
  }
  {
    render::PlotSpec spec;
    spec.title = "Displayed fingertip forces";
    spec.x_label = "time [s]";
    spec.y_label = "|F| [N]";
    static const char* kNames[8] = {"L thumb", "L index", "L middle", "L ring",
                                    "R thumb", "R index", "R middle", "R ring"};
    S s;
    for (int f = 0; f < 8; ++f)
      s.push_back(series(t, kNames[f], f, [f](const MrFrame& m) { return m.force_n[f]; }));
    save_plot((dir / "fingertip_forces.png").string(), spec, s);
  }
  {
    render::PlotSpec spec;
    spec.title = "Loop timing per processed frame (drops: camera frames skipped before it, x10)";
    spec.x_label = "time [s]";
    spec.y_label = "ms / dropped frames x10";
    spec.references = {{"33.3 ms (30 fps)", 33.3, render::plot_colour(7)}};
    save_plot((dir / "loop_timing.png").string(), spec,
              S{series(t, "latency [ms]", 0, [](const MrFrame& m) { return m.latency_ms; }),
                series(t, "pipeline [ms]", 1, [](const MrFrame& m) { return m.pipeline_ms; }),
                series(t, "registration [ms]", 2, [](const MrFrame& m) { return m.registration_ms; }),
                series(t, "servo jitter max [ms]", 3, [](const MrFrame& m) { return m.servo_jitter_max_us * 1e-3; }),
                series(t, "frames dropped before it x10", 4, [](const MrFrame& m) { return 10.0 * m.dropped_before; })});
  }
  {
    render::PlotSpec spec;
    spec.title = "The cube";
    spec.x_label = "time [s]";
    spec.y_label = "deg / mm";
    save_plot((dir / "cube.png").string(), spec,
              S{series(t, "top layer [deg]", 0, [](const MrFrame& m) { return m.u_angle_deg; }),
                series(t, "bottom layer [deg]", 2, [](const MrFrame& m) { return m.d_angle_deg; }),
                series(t, "lift [mm] x10", 1, [](const MrFrame& m) { return 10 * m.lift_mm; })});
  }
}

/// A silhouette loss pooled over `frames` frames as per-frame means per hand [px], and the IoU of
/// the pooled counts.
nlohmann::json silhouette_loss_json(const sim::SilhouetteLoss& sum, std::size_t frames) {
  const double n = frames > 0 ? static_cast<double>(frames) : 1.0;
  nlohmann::json j = {{"frames", frames}, {"iou_pooled", sum.iou()}};
  for (int h = 0; h < 2; ++h)
    j[h == 0 ? "left" : "right"] = {{"missed_palm_px", static_cast<double>(sum.missed_palm[h]) / n},
                                    {"missed_digits_px", static_cast<double>(sum.missed_digits[h]) / n},
                                    {"spill_palm_px", static_cast<double>(sum.spill_palm[h]) / n},
                                    {"spill_digits_px", static_cast<double>(sum.spill_digits[h]) / n}};
  return j;
}

/// "palm missed L/R, spilled L/R; digits missed L/R, spilled L/R" of a per-frame loss
/// (silhouette_loss_json).
std::string silhouette_loss_line(const nlohmann::json& j) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(0);
  const auto pair = [&](const char* k) { o << j["left"][k].get<double>() << "/" << j["right"][k].get<double>(); };
  o << "palm missed ";
  pair("missed_palm_px");
  o << ", spilled ";
  pair("spill_palm_px");
  o << "; digits missed ";
  pair("missed_digits_px");
  o << ", spilled ";
  pair("spill_digits_px");
  return o.str();
}

/// Without a cube: how the object the scripted user reaches for was held (its lift, TruthFrame::
/// lift_mm), over the run and over the frames of the "twist" phase, where the script holds it
/// lifted (RubiksTaskParams::lift): a grip that lost it shows there.
nlohmann::json object_json(const MrTrace& t, const std::vector<std::string>& phases) {
  std::vector<double> all, twist;
  for (std::size_t i = 0; i < t.frames.size(); ++i) {
    all.push_back(t.frames[i].lift_mm);
    if (i < phases.size() && phases[i] == "twist") twist.push_back(t.frames[i].lift_mm);
  }
  return {{"lift_mm_max", quantile(all, 1.0)},
          {"lift_mm_twist_median", quantile(twist, 0.5)},
          {"lift_mm_twist_p5", quantile(twist, 0.05)},
          {"twist_frames", twist.size()}};
}

}  // namespace

int write_mr_report(const std::string& out, const MrTrace& t, const MrSummary& s, std::ostream& os) {
  const fs::path dir(out);
  const int frames = static_cast<int>(t.frames.size());
  const auto reg_ms = column(t, [](const MrFrame& m) { return m.registration_ms; });
  const auto pre_ms = column(t, [](const MrFrame& m) { return m.preprocess_ms; });
  const auto pipe_ms = column(t, [](const MrFrame& m) { return m.pipeline_ms; });
  const auto lat_ms = column(t, [](const MrFrame& m) { return m.latency_ms; });
  const auto iters = column(t, [](const MrFrame& m) { return 0.5 * (m.iterations[0] + m.iterations[1]); });
  const auto occ = column(t, [](const MrFrame& m) { return m.truth[0].occlusion_pct; });
  const auto occ_paper = column(t, [](const MrFrame& m) { return m.truth[0].occlusion_pct_paper; });
  // Contested pixels pooled over the run: the share of all contested pixels shown wrong.
  long contested = 0, contested_wrong = 0, contested_wrong_paper = 0;
  for (const MrFrame& m : t.frames) {
    contested += m.truth[0].contested_pixels;
    contested_wrong += m.truth[0].contested_wrong;
    contested_wrong_paper += m.truth[0].contested_wrong_paper;
  }
  const auto pooled_pct = [contested](long wrong) {
    return contested > 0 ? 100.0 * static_cast<double>(wrong) / static_cast<double>(contested) : 0.0;
  };
  const double contested_pct = pooled_pct(contested_wrong);
  const double contested_pct_paper = pooled_pct(contested_wrong_paper);
  const double contested_mean = frames > 0 ? static_cast<double>(contested) / frames : 0.0;
  std::vector<double> ceiling;
  for (const MrFrame& m : t.frames)
    if (m.ceiling_measured && m.truth[0].real_hand_pixels > 0) ceiling.push_back(m.ceiling_iou);
  // Where the IoU is lost: the fit over its scored frames, and the fit and the ceiling over the
  // ceiling's frames (like for like).
  sim::SilhouetteLoss loss_fit, loss_fit_ceiling_frames, loss_ceiling;
  std::size_t scored = 0;
  for (const MrFrame& m : t.frames) {
    if (m.truth[0].scored_in_image()) {
      loss_fit += m.truth[0].loss;
      ++scored;
    }
    if (m.ceiling_measured && m.truth[0].real_hand_pixels > 0) {
      loss_fit_ceiling_frames += m.truth[0].loss;
      loss_ceiling += m.ceiling_loss;
    }
  }
  const auto joint_floor = column(t, [](const MrFrame& m) { return 0.5 * (m.truth[0].joint_px_floor[0] + m.truth[0].joint_px_floor[1]); });
  const auto cap_res = column(t, [](const MrFrame& m) { return std::max(m.truth_cap_residual_mm[0], m.truth_cap_residual_mm[1]); });
  // Frames delivered per second of the run: processed frames over the span of their exposures
  // (the camera runs at its rate; every frame the frame thread could not take is missing here).
  const double span = frames > 1 ? t.frames.back().t_s - t.frames.front().t_s : 0;
  const double fps = span > 0 ? (frames - 1) / span : 0;

  nlohmann::json reg = registration_json(t, 0);
  reg["ms_per_frame_median"] = quantile(reg_ms, 0.5);
  reg["ms_per_frame_p95"] = quantile(reg_ms, 0.95);
  reg["preprocess_ms_median"] = quantile(pre_ms, 0.5);
  reg["iterations_mean"] = mean(iters);
  reg["method"] = s.main_silhouette ? "joint-balls + silhouette" : "joint-balls (paper)";
  const nlohmann::ordered_json by_phase = by_phase_json(t, s.phases);
  if (!by_phase.empty()) reg["by_phase"] = nlohmann::json::parse(by_phase.dump());
  nlohmann::json other = registration_json(t, 1);
  other["method"] = s.main_silhouette ? "joint-balls (paper)" : "joint-balls + silhouette";
  reg["comparison"] = other;
  reg["silhouette_loss"] = silhouette_loss_json(loss_fit, scored);
  reg["silhouette_loss_on_ceiling_frames"] = silhouette_loss_json(loss_fit_ceiling_frames, ceiling.size());
  const nlohmann::json ceiling_loss = silhouette_loss_json(loss_ceiling, ceiling.size());
  // The hands' sizes as the registration estimated them (its starting profile when not
  // personalised), beside ground_truth.hand_shape.
  if (!t.frames.empty()) {
    nlohmann::json shape;
    for (int h = 0; h < 2; ++h) {
      const registration::ShapeEstimate& e = t.frames.back().shape[h];
      shape[h == 0 ? "left" : "right"] = {{"length_m", e.length_m},
                                          {"width_m", e.width_m},
                                          {"sigma_length_m", e.sigma_length_m},
                                          {"sigma_width_m", e.sigma_width_m},
                                          {"thickness", e.thickness},
                                          {"sigma_thickness", e.sigma_thickness},
                                          {"length_frozen", e.length_frozen},
                                          {"width_frozen", e.width_frozen},
                                          {"thickness_frozen", e.thickness_frozen},
                                          {"keyframes", e.keyframes},
                                          {"solves", e.solves},
                                          {"steps_rejected", e.steps_rejected},
                                          {"palm_chords", e.palm_chords},
                                          {"cap_reach_m", e.cap_reach_m},
                                          {"sigma_cap_reach_m", e.sigma_cap_reach_m},
                                          {"cap_reach_samples", e.cap_reach_samples},
                                          {"sections", e.sections}};
    }
    shape["personalised"] = s.personalised;
    reg["hand_shape"] = shape;
  }

  nlohmann::json report = {
      {"ended_by", s.ended_by},
      {"frames", frames},
      {"seconds", s.seconds},
      {"wall_seconds", s.wall_s},
      {"threads", [&] {  // CPU seconds by thread name over the run (start-up included)
         nlohmann::json by_name = nlohmann::json::object();
         for (const core::ThreadCpu& c : s.thread_cpu) by_name[c.name] = {{"cpu_s", c.cpu_s}, {"count", c.threads}};
         return by_name;
       }()},
      {"dropped_frames", s.dropped},
      {"image", {{"width", s.width}, {"height", s.height}}},
      {"scene", s.scene},
      {"user_hand", s.user_hand},
      {"user_hand_profile", s.user_profile},
      {"shaped_fingers", s.shaped_fingers},
      {"ring_on_side", s.ring_on_side},
      {"fit_margin_rad", s.fit_margin_rad},
      {"bending_wrists", s.bending_wrists},
      {"haptic", [&] {
         nlohmann::json h = servo_timing_json(s.servo);
         h.update({{"deadline_misses", s.servo.deadline_misses},
                   {"stale_force_cycles", s.servo.stale_force_cycles},
                   {"faults", device::fault_names(s.servo.faults)},
                   {"fault_message", s.servo.fault_message}});
         return h;
       }()},
      {"physics",
       {{"rate_hz", s.physics.rate_hz},
        {"step_ms_median", s.physics.step_ms_median},
        {"step_ms_p99", s.physics.step_ms_p99},
        {"late_steps", s.physics.late_steps},
        {"realtime_scheduling", s.physics.realtime_scheduling},
        {"memory", physics_memory_json(s.physics.memory)},
        {"mujoco_warnings", s.mujoco_warnings},
        {"mujoco_warning_kinds", [&] {
           nlohmann::json j = nlohmann::json::object();
           for (const auto& w : s.mujoco_warning_kinds) j[w.kind] = w.count;
           return j;
         }()},
        {"mujoco_log", s.mujoco_log}}},
      {"registration", reg},
      {"composite",
       {{"mode", s.compositor},
        {"occlusion_error_pct", mean(occ)},
        {"occlusion_error_pct_paper", mean(occ_paper)},
        {"occlusion_error_pct_p95", quantile(occ, 0.95)},
        {"contested_error_pct", contested_pct},
        {"contested_error_pct_paper", contested_pct_paper},
        {"contested_pixels_mean", contested_mean}}},
      {"pipeline",
       {{"fps", fps},
        {"latency_ms_median", quantile(lat_ms, 0.5)},
        {"latency_ms_p95", quantile(lat_ms, 0.95)},
        {"ms_per_frame_median", quantile(pipe_ms, 0.5)},
        {"capacity_fps", quantile(pipe_ms, 0.5) > 0 ? 1000.0 / quantile(pipe_ms, 0.5) : 0.0},
        {"dropped_frames", s.dropped},  // also at the top level (older readers)
        {"dropped_pct", frames + s.dropped > 0 ? 100.0 * s.dropped / static_cast<double>(frames + s.dropped) : 0.0},
        {"camera_skipped_frames", s.camera_skipped},
        {"output_waits", s.output_waits},
        {"output_wait_ms", s.output_wait_ms},
        {"frame_thread_fifo", s.frame_realtime},
        {"stage_ms_median",
         {{"chroma_key", quantile(column(t, [](const MrFrame& m) { return m.stages.key_ms; }), 0.5)},
          {"bracelets", quantile(column(t, [](const MrFrame& m) { return m.stages.bracelet_ms; }), 0.5)},
          {"silhouette_evidence", quantile(column(t, [](const MrFrame& m) { return m.stages.distance_ms; }), 0.5)},
          {"registration", quantile(column(t, [](const MrFrame& m) { return m.stages.registration_ms; }), 0.5)},
          {"render", quantile(column(t, [](const MrFrame& m) { return m.stages.render_ms; }), 0.5)},
          {"composite", quantile(column(t, [](const MrFrame& m) { return m.stages.composite_ms; }), 0.5)}}},
        {"simulation_ms_median",
         {{"synthetic_camera", quantile(column(t, [](const MrFrame& m) { return m.film_ms; }), 0.5)},
          {"truth_and_comparison", quantile(column(t, [](const MrFrame& m) { return m.truth_ms; }), 0.5)},
          {"video_output", quantile(column(t, [](const MrFrame& m) { return m.output_ms; }), 0.5)}}}}},
      {"cube",
       {{"present", s.has_cube},
        {"turns_completed", s.turns},
        {"turns_planned", s.task.turns_planned},
        {"turns_other_faces", s.other_turns},
        {"turn_attempts", s.task.attempts},
        {"retries", {{"turn", s.task.retries_turn}, {"grasp", s.task.retries_grasp}}},
        {"gave_up", s.task.gave_up},
        {"grip_firmed_s", s.task.firm_since_s},
        {"solved", s.solved},
        {"facelets", s.facelets},
        {"face_angles_deg", [&] {
           nlohmann::json j = nlohmann::json::object();
           for (const auto& [f, a] : s.face_deg) j[std::string(1, f)] = a;
           return j;
         }()}}},
      {"ground_truth", {{"cap_residual_mm_max", quantile(cap_res, 1.0)},
                        {"cap_residual_mm_median", quantile(cap_res, 0.5)},
                        {"model_ceiling_iou", mean(ceiling)},
                        {"model_ceiling_iou_p5", quantile(ceiling, 0.05)},
                        {"model_ceiling_frames", ceiling.size()},
                        {"model_ceiling_loss", ceiling_loss},
                        {"joint_px_floor", mean(joint_floor)},
                        {"hand_shape", {{"length_m", s.user_length_m}, {"width_m", s.user_width_m}, {"cap_reach_m", s.user_cap_reach_m}}}}},
      {"video", {{"path", s.video_path}, {"format", s.video_format}}}};
  // Without a cube, the object the user reached for instead: how high it was held while twisted.
  const nlohmann::json object = s.has_cube ? nlohmann::json() : object_json(t, s.phases);
  if (!s.has_cube) report["object"] = object;
  nlohmann::json forces = nlohmann::json::array();
  int touching = 0;
  for (int f = 0; f < 8; ++f) {
    const auto v = column(t, [f](const MrFrame& m) { return m.force_n[f]; });
    const double fmax = quantile(v, 1.0);
    forces.push_back(fmax);
    touching += fmax > 0.5 ? 1 : 0;
  }
  report["haptic"]["force_max_n"] = forces;
  require_finite_json(report, (dir / "report.json").string());
  // Whole or not at all (a directory or unwritable path there is an error naming it, exit 2).
  core::write_file_atomic((dir / "report.json").string(), json_text(report, 2) + "\n");
  write_frames_csv((dir / "frames.csv").string(), t, s.phases);
  if (frames > 1) write_plots(dir, t, s);

  const std::size_t scored_in_image = reg["frames_scored_in_image"].get<std::size_t>();
  os << "\nresult (" << frames << " frames in " << std::fixed << std::setprecision(1) << s.wall_s
     << " s, " << s.dropped << " dropped"
     << (s.camera_skipped > 0 ? ", " + std::to_string(s.camera_skipped) + " not filmed in time by the simulated camera" : std::string())
     << "):\n"
     << std::setprecision(3)
     << (scored_in_image < static_cast<std::size_t>(frames)
             ? "  warning        the hands were out of the camera's view in " +
                   std::to_string(static_cast<std::size_t>(frames) - scored_in_image) +
                   " frames: IoU and joints are over the other " + std::to_string(scored_in_image) +
                   " (frames_scored_in_image); check the camera's pose and the scene\n"
             : std::string())
     << "  registration   "
     << (scored_in_image == 0
             ? std::string("IoU n/a, joints n/a (no hand in view in any frame)")
             : "IoU mean " + fixed_text(reg["iou_mean"].get<double>(), 3) + " (p5 " +
                   fixed_text(reg["iou_p5"].get<double>(), 3) + "), joints " +
                   fixed_text(reg["joint_px_mean"].get<double>(), 2) + " px")
     << ", fingertip " << std::setprecision(2) << reg["fingertip_mm_mean"].get<double>() << " mm, wrist depth " << std::setprecision(1) << reg["wrist_depth_mm_mean"].get<double>() << " mm, "
     << std::setprecision(2) << reg["ms_per_frame_median"].get<double>() << " ms/frame (both hands), "
     << reg["iterations_mean"].get<double>() << " iterations\n"
     << "  model ceiling  IoU " << std::setprecision(3) << mean(ceiling)
     << " (the model's skin at the true pose with the user's sizes)\n"
     << (ceiling.empty() ? std::string()
                         : "  IoU lost       px per frame, left/right, on the ceiling's frames:\n"
                           "                   fit      " + silhouette_loss_line(reg["silhouette_loss_on_ceiling_frames"]) +
                           "\n                   ceiling  " + silhouette_loss_line(ceiling_loss) + "\n")
     << by_phase_line(by_phase)
     << "  comparison     " << other["method"].get<std::string>() << ": IoU "
     << std::setprecision(3) << other["iou_mean"].get<double>() << ", fingertip "
     << std::setprecision(2) << other["fingertip_mm_mean"].get<double>() << " mm, joints "
     << other["joint_px_mean"].get<double>() << " px\n"
     << "  compositing    occlusion error " << mean(occ) << " % (" << s.compositor
     << "), paper's method " << mean(occ_paper) << " %; contested pixels (hand over an object, "
     << std::setprecision(0) << contested_mean << " per frame) " << std::setprecision(2)
     << contested_pct << " % wrong, paper's " << contested_pct_paper << " %\n"
     << "  pipeline       " << std::setprecision(1) << fps << " fps, latency median "
     << quantile(lat_ms, 0.5) << " ms, " << quantile(pipe_ms, 0.5) << " ms/frame (capacity "
     << (quantile(pipe_ms, 0.5) > 0 ? 1000.0 / quantile(pipe_ms, 0.5) : 0.0) << " fps)\n"
     << "  haptics        servo " << s.servo.rate_hz << " Hz, jitter p99 " << s.servo.jitter_p99_us
     << " us, overruns " << s.servo.overruns << " (" << s.servo.deadline_misses
     << " cycles without force, " << s.servo.stale_force_cycles << " on stale physics), faults " << device::fault_names(s.servo.faults)
     << "; physics step median " << std::setprecision(2) << s.physics.step_ms_median << " ms\n"
     << "  contact        " << touching << " of 8 fingertips felt more than 0.5 N\n";
  if (!s.has_cube)
    os << "  object         lifted " << std::setprecision(1) << object["lift_mm_max"].get<double>()
       << " mm at most; over the twist (" << object["twist_frames"].get<std::size_t>() << " frames) "
       << object["lift_mm_twist_median"].get<double>() << " mm, p5 " << object["lift_mm_twist_p5"].get<double>()
       << " mm\n";
  os << "  cube           "
     << (s.has_cube ? std::to_string(s.turns) + " of " + std::to_string(s.task.turns_planned) +
                          " layer turns completed (" + std::to_string(s.task.retries_turn) +
                          " turn and " + std::to_string(s.task.retries_grasp) + " grasp retries" +
                          (s.task.gave_up ? ", then out of time" : "") + ")" +
                          (s.other_turns > 0 ? ", and " + std::to_string(s.other_turns) +
                                                   " quarter turns of other layers"
                                             : "") +
                          ", " +
                          (s.solved ? "solved" : "not solved")
                    : std::string("none in this scene"))
     << "\n"
     << "wrote " << (dir / "report.json").string() << ", plots (*.png), keyframes/"
     << (s.video_path.empty() ? "" : ", " + s.video_path) << "\n";
  return 0;
}

}  // namespace spidar::session
