// spidar-mr demo: until the mixed-reality pipeline exists, a walkthrough of the SPIDAR-8 device
// maths on a scripted two-handed grasp, with simulated encoders and motor drives:
//   power-up (arbitrary wrapping counters) → pole calibration → multi-point jig calibration →
//   1 kHz grasp: counts → lengths → positions → contact force → tensions → DAC → displayed force.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <random>

#include "spidar/session/json_text.hpp"
#include "spidar/session/data_path.hpp"
#include "spidar/session/finite_json.hpp"
#include "spidar/session/scenarios.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/core/units.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::session {
namespace {

using namespace spidar::strings;

/// A virtual box felt through a penalty spring (the grasped object until physics lands).
struct VirtualBox {
  Vec3 p_W_centre = Vec3::Zero();
  Vec3 half = Vec3::Constant(0.0285);  // a 5.7 cm Rubik's cube [m]
  double stiffness = 1000.0;           // [N/m], as in the SPIDAR-8 grasp application

  /// Force on a fingertip at p [N]: pushes out through the nearest face when inside.
  Vec3 force(const Vec3& p) const {
    const Vec3 d = p - p_W_centre;
    const Vec3 depth = half - d.cwiseAbs();
    if ((depth.array() <= 0.0).any()) return Vec3::Zero();
    int axis = 0;
    depth.minCoeff(&axis);
    Vec3 f = Vec3::Zero();
    f[axis] = stiffness * depth[axis] * (d[axis] >= 0 ? 1.0 : -1.0);
    return f;
  }
};

/// Scripted fingertip path: open hand → grasp (3 mm into the faces) → slide up 2 cm → release.
/// (The ring finger on the top face slides out of contact as it rises.)
Vec3 scripted_fingertip(int finger, double t, double duration) {
  const bool right = finger >= 4;
  const int k = finger % 4;  // thumb, index, middle, ring
  const double sx = right ? 1.0 : -1.0;
  const double h = 0.0285, press = 0.003;
  // Contact points: thumb on the front face, index and middle on the back face, ring on the top
  // face (its front-top unit cannot push a finger backwards; see the force-cone table).
  Vec3 grasp, open;
  if (k == 3) {
    grasp = Vec3(sx * 0.018, -0.004, h - press);
    open = grasp + Vec3(sx * 0.03, 0.0, 0.04);
  } else {
    const double y_face = k == 0 ? -(h - press) : (h - press);
    const double z_rest = k == 0 ? -0.005 : -0.012 + 0.011 * (k - 1);
    grasp = Vec3(sx * (0.012 + 0.004 * k), y_face, z_rest);
    open = grasp + Vec3(sx * 0.03, (k == 0 ? -1.0 : 1.0) * 0.04, 0.02);
  }
  const double s = t / duration;
  auto smooth = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3 - 2 * x);
  };
  Vec3 p = open + (grasp - open) * smooth(s / 0.3);                      // close
  p.z() += 0.02 * smooth((s - 0.35) / 0.3);                              // slide up
  p += (open - grasp) * smooth((s - 0.8) / 0.2);                         // release
  return p;
}

std::string fmt_vec(const Vec3& v, int prec = 3) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(prec) << "(" << std::setw(prec + 4) << v.x() << ","
     << std::setw(prec + 4) << v.y() << "," << std::setw(prec + 4) << v.z() << ")";
  return os.str();
}

/// The simulated device: true encoder channels (per-string scale errors, arbitrary power-up
/// counts) that the host does not know.
struct SimulatedStrings {
  std::vector<std::vector<EncoderChannel>> truth;  // per finger, per string
  int bits = 24;
  double count_noise = 0.5;  // counts RMS (encoder edge jitter, string stretch)

  std::vector<std::int64_t> read_raw(const PointGeometry& g, int f, const Vec3& p,
                                     std::mt19937_64& rng) const {
    std::normal_distribution<double> noise(0.0, count_noise);
    std::vector<std::int64_t> raw(g.n);
    for (int i = 0; i < g.n; ++i) {
      const double l = (g.p_WA[i] - p).norm();
      const auto ideal = length_to_counts(truth[f][i], l);
      raw[i] = wrap_counter(ideal + std::llround(noise(rng)), bits);
    }
    return raw;
  }
};

/// Position error [m] of every finger at random workspace points around the cube.
double workspace_error_rms(const DeviceConfig& cfg, const SimulatedStrings& dev,
                           const std::vector<std::vector<EncoderChannel>>& cal,
                           std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-0.08, 0.08);
  double sum2 = 0;
  int n = 0;
  for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
    std::vector<Vec3> pts;
    for (int j = 0; j < 200; ++j) pts.emplace_back(u(rng), u(rng), u(rng));
    const auto e = position_error_rms(cfg.fingers[f].geometry, dev.truth[f], cal[f], pts);
    sum2 += e.value() * e.value();
    ++n;
  }
  return std::sqrt(sum2 / n);
}

}  // namespace

void run_strings_walkthrough(const ScenarioOptions& a, std::ostream& out) {
  using namespace spidar::strings;
  const double seconds = a.seconds > 0 ? a.seconds : 3.0;
  namespace fs = std::filesystem;
  const auto cfg = load_device_config(resolve_data_path(a.config));
  if (!(seconds > 0 && seconds <= 600)) throw SpidarError("--seconds: expected (0, 600]");
  if (!(a.rate_hz >= 10 && a.rate_hz <= 20000)) throw SpidarError("--rate: expected 10..20000 Hz");
  fs::create_directories(a.out);
  std::mt19937_64 rng(a.seed);
  const auto limits = cfg.effective_limits();
  const int nf = static_cast<int>(cfg.fingers.size());

  out << "spidar-mr demo: device maths walkthrough on " << cfg.name << " (" << cfg.source
            << ")\n  " << nf << " fingers, " << cfg.string_count() << " strings; tension "
            << limits.t_min << "-" << limits.t_max << " N (drive: "
            << std::setprecision(4) << volts_per_newton(cfg.motor) << " V/N, saturates at "
            << max_drive_tension(cfg.motor) << " N)\n\n";

  // 1. Power-up: the true device differs from the config (scale ±1.5 %), counters start anywhere.
  SimulatedStrings dev;
  dev.bits = cfg.counter_bits;
  std::normal_distribution<double> scale(1.0, 0.015);
  std::uniform_int_distribution<std::int64_t> power_up(-(1 << 23), (1 << 23) - 1);
  for (const auto& f : cfg.fingers) {
    std::vector<EncoderChannel> truth;
    for (int i = 0; i < f.geometry.n; ++i) {
      EncoderChannel ch = f.channels[i];
      ch.metres_per_count *= scale(rng);
      const double l_pole = (f.geometry.p_WA[i] - cfg.p_W_centre).norm();
      ch.length_at_zero = l_pole - ch.sign * ch.metres_per_count * static_cast<double>(power_up(rng));
      truth.push_back(ch);
    }
    dev.truth.push_back(truth);
  }
  std::vector<std::vector<CounterUnwrapper>> unwrap(nf);
  for (int f = 0; f < nf; ++f) unwrap[f].assign(cfg.fingers[f].geometry.n, CounterUnwrapper(cfg.counter_bits));

  // 2. Pole calibration: each fingertip cap touches the pole by hand (σ = 3 mm per axis).
  std::normal_distribution<double> hand_noise(0.0, 0.003);
  std::vector<std::vector<EncoderChannel>> pole_cal(nf);
  for (int f = 0; f < nf; ++f) {
    const auto& g = cfg.fingers[f].geometry;
    const Vec3 placed = cfg.p_W_centre + Vec3(hand_noise(rng), hand_noise(rng), hand_noise(rng));
    const auto raw = dev.read_raw(g, f, placed, rng);
    std::vector<std::int64_t> counts(g.n);
    for (int i = 0; i < g.n; ++i) counts[i] = unwrap[f][i].update(raw[i]);
    pole_cal[f] = pole_calibrate(g, cfg.fingers[f].channels, counts, cfg.p_W_centre).value();
  }
  const double pole_err = workspace_error_rms(cfg, dev, pole_cal, rng);

  // 3. Multi-point calibration on a 3×3×3 jig, 6 cm pitch, placement noise σ = 0.5 mm.
  std::normal_distribution<double> jig_noise(0.0, 0.0005);
  std::vector<std::vector<EncoderChannel>> jig_cal(nf);
  double fit_rms_max = 0;
  const auto jig = jig_grid(cfg.p_W_centre, 0.06, 3);
  for (int f = 0; f < nf; ++f) {
    const auto& g = cfg.fingers[f].geometry;
    std::vector<JigSample> samples;
    for (const Vec3& p : jig) {
      const Vec3 placed = p + Vec3(jig_noise(rng), jig_noise(rng), jig_noise(rng));
      const auto raw = dev.read_raw(g, f, placed, rng);
      JigSample s{p, {}};
      for (int i = 0; i < g.n; ++i) s.counts.push_back(unwrap[f][i].update(raw[i]));
      samples.push_back(s);
    }
    const auto fits = fit_multipoint(g, samples).value();
    for (const auto& fit : fits) {
      jig_cal[f].push_back(fit.channel);
      fit_rms_max = std::max(fit_rms_max, fit.residual_rms);
    }
  }
  const double jig_err = workspace_error_rms(cfg, dev, jig_cal, rng);
  out << std::fixed << std::setprecision(2)
            << "calibration (position error RMS over random points within 8 cm of the centre):\n"
            << "  pole, manual placement sigma 3 mm   " << units::m_to_mm(pole_err) << " mm\n"
            << "  3x3x3 jig, placement sigma 0.5 mm  " << units::m_to_mm(jig_err)
            << " mm   (worst string fit residual " << units::m_to_mm(fit_rms_max) << " mm)\n\n";

  // 4. Force cones at the grasp: a 3-string unit only pulls toward its own corner, and t_min on
  // every string adds a baseline force. Share of directions displayable at 2 N, the baseline,
  // and whether the contact push the grasp needs is displayable.
  out << "force cones at the grasp point (share of directions displayable at 2 N; baseline "
               "force of t_min on all strings; the contact push of the grasp):\n";
  const VirtualBox box;
  nlohmann::json cones = nlohmann::json::array();
  for (int f = 0; f < nf; ++f) {
    const auto& g = cfg.fingers[f].geometry;
    const Vec3 p = scripted_fingertip(f, 0.32 * seconds, seconds);  // just grasped
    const auto U = string_directions(g, p).value();
    int ok = 0;
    const int m = 2000;
    for (int k = 0; k < m; ++k) {  // Fibonacci sphere
      const double z = 1.0 - (2.0 * k + 1.0) / m, r = std::sqrt(1.0 - z * z);
      const double phi = k * units::kPi * (3.0 - std::sqrt(5.0));
      const Vec3 dir(r * std::cos(phi), r * std::sin(phi), z);
      ok += solve_tensions(U, 2.0 * dir, limits).value().reachable;
    }
    const Vec3 baseline = U * StringVec::Constant(g.n, limits.t_min);
    const Vec3 push = box.force(p);
    const auto sol = solve_tensions(U, push, limits).value();
    const double along = push.norm() > 0 ? sol.f_displayed.dot(push.normalized()) / push.norm() : 0;
    out << "  " << std::left << std::setw(13) << cfg.fingers[f].name << std::right
              << std::setprecision(1) << std::setw(5) << 100.0 * ok / m << " %   baseline "
              << fmt_vec(baseline, 2) << "   push " << fmt_vec(push, 2) << " -> "
              << fmt_vec(sol.f_displayed, 2) << (sol.reachable ? "" : " (projected)") << "\n";
    cones.push_back({{"finger", cfg.fingers[f].name},
                     {"displayable_share", static_cast<double>(ok) / m},
                     {"baseline_force_n", to_json(baseline)},
                     {"grasp_push_n", to_json(push)},
                     {"grasp_push_displayed_n", to_json(sol.f_displayed)},
                     {"grasp_push_fidelity", along}});
  }

  // 5. The scripted grasp at the servo rate.
  const double dt = 1.0 / a.rate_hz;
  const int steps = static_cast<int>(std::lround(seconds * a.rate_hz));
  const int print_every = std::max(1, steps / 12);
  std::ostringstream csv;  // written whole (write_file_atomic) after the grasp, never cut mid-row
  csv << "t,finger,x_true,y_true,z_true,x_est,y_est,z_est,err_mm,fx_des,fy_des,fz_des,"
         "fx_disp,fy_disp,fz_disp,reachable,t0,t1,t2,dac0,dac1,dac2\n";
  std::vector<double> err_max(nf, 0), err_sum2(nf, 0), force_max(nf, 0), force_gap_max(nf, 0);
  std::vector<int> contact(nf, 0);
  std::vector<double> fidelity_sum(nf, 0.0);
  double pos_ns = 0, ten_ns = 0;
  out << "\nscripted grasp, " << seconds << " s at " << a.rate_hz
            << " Hz (left index and right thumb shown; all fingers in walkthrough.csv):\n"
            << "     t  finger        position est [m]          err[mm]  desired F [N]"
               "            displayed F [N]          tensions [N]\n";
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    for (int f = 0; f < nf; ++f) {
      const auto& fc = cfg.fingers[f];
      const Vec3 p_true = scripted_fingertip(f, t, seconds);
      const auto raw = dev.read_raw(fc.geometry, f, p_true, rng);
      StringVec l(fc.geometry.n);
      for (int i = 0; i < fc.geometry.n; ++i)
        l[i] = counts_to_length(jig_cal[f][i], unwrap[f][i].update(raw[i]));
      const auto t0 = std::chrono::steady_clock::now();
      const auto est = solve_position(fc.geometry, std::span<const double>(l.data(), l.size())).value();
      const auto t1 = std::chrono::steady_clock::now();
      const Vec3 f_des = box.force(est.p_WF);  // felt where the device thinks the finger is
      const auto sol = solve_tensions(fc.geometry, est.p_WF, f_des, limits).value();
      const auto t2 = std::chrono::steady_clock::now();
      pos_ns += std::chrono::duration<double, std::nano>(t1 - t0).count();
      ten_ns += std::chrono::duration<double, std::nano>(t2 - t1).count();
      // What the strings actually pull: DAC quantisation, then back through the drive.
      Vec3 f_out = Vec3::Zero();
      std::vector<std::int32_t> dac;
      const auto U = string_directions(fc.geometry, p_true).value();
      for (int i = 0; i < fc.geometry.n; ++i) {
        const auto cmd = tension_to_command(cfg.motor, sol.t[i]);
        dac.push_back(cmd.dac);
        f_out += command_to_tension(cfg.motor, cmd.dac) * U.col(i);
      }
      const double err = (est.p_WF - p_true).norm();
      err_max[f] = std::max(err_max[f], err);
      err_sum2[f] += err * err;
      force_max[f] = std::max(force_max[f], f_out.norm());
      if (f_des.norm() > 0.5) {  // in contact: how much of the push the strings display
        force_gap_max[f] = std::max(force_gap_max[f], (f_out - f_des).norm());
        fidelity_sum[f] += f_out.dot(f_des) / f_des.squaredNorm();
        ++contact[f];
      }
      csv << t << ',' << f << ',' << p_true.x() << ',' << p_true.y() << ',' << p_true.z() << ','
          << est.p_WF.x() << ',' << est.p_WF.y() << ',' << est.p_WF.z() << ',' << err * 1e3 << ','
          << f_des.x() << ',' << f_des.y() << ',' << f_des.z() << ',' << f_out.x() << ','
          << f_out.y() << ',' << f_out.z() << ',' << sol.reachable;
      for (int i = 0; i < 3; ++i) csv << ',' << (i < sol.t.size() ? sol.t[i] : 0.0);
      for (int i = 0; i < 3; ++i) csv << ',' << (i < static_cast<int>(dac.size()) ? dac[i] : 0);
      csv << '\n';
      if (k % print_every == 0 && (f == 1 || f == 4)) {
        std::ostringstream ts;
        ts << std::fixed << std::setprecision(2);
        for (int i = 0; i < sol.t.size(); ++i) ts << (i ? " " : "") << std::setw(5) << sol.t[i];
        out << std::fixed << std::setprecision(2) << std::setw(6) << t << "  "
                  << std::left << std::setw(12) << fc.name << std::right << fmt_vec(est.p_WF)
                  << std::setw(7) << std::setprecision(2) << err * 1e3 << "  "
                  << fmt_vec(f_des, 2) << "  " << fmt_vec(f_out, 2) << "  " << ts.str()
                  << (sol.reachable ? "" : "  (outside cone)") << "\n";
      }
    }
  }
  core::write_file_atomic((fs::path(a.out) / "walkthrough.csv").string(), csv.str());
  const int samples = (steps + 1);
  out << "\nper finger over the run (fidelity: displayed force along the desired push / "
               "desired, in contact):\n  finger        err RMS [mm]  err max [mm]  max |F| [N]"
               "  contact [ms]  fidelity  largest gap [N]\n";
  nlohmann::json fingers = nlohmann::json::array();
  for (int f = 0; f < nf; ++f) {
    const double rms = std::sqrt(err_sum2[f] / samples);
    out << "  " << std::left << std::setw(13) << cfg.fingers[f].name << std::right
              << std::setprecision(3) << std::setw(12) << rms * 1e3 << std::setw(14)
              << err_max[f] * 1e3 << std::setw(13) << force_max[f] << std::setw(14)
              << std::setprecision(0) << contact[f] * dt * 1e3 << std::setprecision(2)
              << std::setw(10) << (contact[f] ? fidelity_sum[f] / contact[f] : 0.0)
              << std::setw(17) << force_gap_max[f] << "\n";
    fingers.push_back({{"name", cfg.fingers[f].name},
                       {"position_error_rms_mm", rms * 1e3},
                       {"position_error_max_mm", err_max[f] * 1e3},
                       {"force_max_n", force_max[f]},
                       {"contact_s", contact[f] * dt},
                       {"force_fidelity_mean", contact[f] ? fidelity_sum[f] / contact[f] : 0.0},
                       {"force_gap_max_n", force_gap_max[f]}});
  }
  const double per = 1.0 / (static_cast<double>(samples) * nf);
  out << std::setprecision(0) << "\nsolver time per fingertip (wall clock, this run): position "
            << pos_ns * per << " ns, tensions " << ten_ns * per
            << " ns (make bench gives the careful figures)\n";
  nlohmann::json report = {
      {"config", cfg.source},
      {"seconds", seconds},
      {"rate_hz", a.rate_hz},
      {"seed", a.seed},
      {"calibration",
       {{"pole_position_error_rms_mm", pole_err * 1e3},
        {"jig_position_error_rms_mm", jig_err * 1e3},
        {"jig_fit_residual_rms_max_mm", fit_rms_max * 1e3}}},
      {"force_cones", cones},
      {"fingers", fingers},
      {"solver_ns_per_fingertip", {{"position", pos_ns * per}, {"tension", ten_ns * per}}}};
  require_finite_json(report, (fs::path(a.out) / "report.json").string());
  core::write_file_atomic((fs::path(a.out) / "report.json").string(), json_text(report, 2) + "\n");
  out << "wrote " << (fs::path(a.out) / "walkthrough.csv").string() << " and "
            << (fs::path(a.out) / "report.json").string() << "\n";
}

}  // namespace spidar::session
