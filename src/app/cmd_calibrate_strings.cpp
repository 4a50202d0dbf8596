// spidar-mr calibrate-strings: pole calibration finger by finger (the paper's), or the multi-point
// jig, with a stability check before each sample; the results go back into the device config,
// whose previous version is kept beside it (file.yaml.bak-YYYYmmdd-HHMMSS).
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cli_support.hpp"
#include "commands.hpp"
#include "device_backends.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/strings/encoder.hpp"
#include "spidar/strings/position.hpp"
#include "string_calibration.hpp"

namespace spidar::app {
namespace {

double pole_error_mm(const strings::FingerConfig& f, std::span<const strings::EncoderChannel> ch,
                     std::span<const std::int64_t> counts, const Vec3& p_W_pole) {
  const auto p_W = fingertip_from_counts(f, ch, counts);
  return p_W ? (*p_W - p_W_pole).norm() * 1e3 : NAN;
}

}  // namespace

Action add_calibrate_strings(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "calibrate-strings",
      "Calibrate the string encoders: pole (finger by finger at the frame centre) or multi-point "
      "jig; writes the device config back, keeping the previous version");
  struct Args {
    BackendArgs backend;
    std::string fingers;
    int jig = 0;
    double jig_spacing = 0.04;
    double hold_s = 0.5;
    double tolerance_mm = 0.5;
    double near_mm = 0;
    double timeout_s = 30;
    bool dry_run = false;
  };
  auto a = std::make_shared<Args>();
  add_backend_options(*cmd, a->backend);
  cmd->add_option("--fingers", a->fingers, "comma-separated finger names or indices (default: all, in order)");
  cmd->add_option("--jig", a->jig,
                  "multi-point jig with N x N x N points around the frame centre (N >= 2; fits offsets, "
                  "metres per count and signs); 0 = pole calibration")
      ->capture_default_str();
  cmd->add_option("--jig-spacing", a->jig_spacing, "jig point spacing [m]")->capture_default_str();
  cmd->add_option("--hold", a->hold_s, "the fingertip must hold still this long before a sample [s]")
      ->capture_default_str();
  cmd->add_option("--tolerance", a->tolerance_mm, "largest string movement while holding still [mm]")
      ->capture_default_str();
  cmd->add_option("--near", a->near_mm,
                  "also require the fingertip this close to the target by the present calibration [mm] "
                  "(0 = off: before a first calibration the counters may be zeroed anywhere)")
      ->capture_default_str();
  cmd->add_option("--timeout", a->timeout_s, "give up on a finger after this long [s]")->capture_default_str();
  cmd->add_flag("--dry-run", a->dry_run, "print the results, do not write the config");
  return [a] {
    if (!(a->jig == 0 || (a->jig >= 2 && a->jig <= 5)))
      throw UsageError("--jig: expected 0 (pole) or 2 to 5, got " + std::to_string(a->jig));
    if (!(a->jig_spacing > 0.005 && a->jig_spacing < 0.2)) throw UsageError("--jig-spacing: expected 0.005 to 0.2 m");
    if (!(a->hold_s >= 0.05 && a->hold_s <= 10)) throw UsageError("--hold: expected 0.05 to 10 s");
    if (!(a->tolerance_mm > 0 && a->tolerance_mm <= 20)) throw UsageError("--tolerance: expected 0 to 20 mm");
    if (!(a->near_mm >= 0 && a->near_mm <= 1000)) throw UsageError("--near: expected 0 to 1000 mm");
    if (!(a->timeout_s > 0 && a->timeout_s <= 600)) throw UsageError("--timeout: expected 0 to 600 s");
    const std::string path = resolve_data_path(a->backend.config);
    const strings::DeviceConfig cfg = strings::load_device_config(path);
    std::vector<int> fingers;
    if (a->fingers.empty()) {
      for (int f = 0; f < static_cast<int>(cfg.fingers.size()); ++f) fingers.push_back(f);
    } else {
      std::stringstream ss(a->fingers);
      std::string name;
      while (std::getline(ss, name, ',')) fingers.push_back(find_finger(cfg, name));
    }
    std::vector<Vec3> targets = {cfg.p_W_centre};
    if (a->jig > 0) targets = strings::jig_grid(cfg.p_W_centre, a->jig_spacing, a->jig);

    // The device: the simulated SPIDAR with a simulated user who follows the guidance, stepped
    // 1 ms per reading (simulated time, as fast as it computes), or the hardware in real time.
    const bool sim = a->backend.backend == "sim";
    std::shared_ptr<CalibrationUser> user;
    std::unique_ptr<device::Device> dev;
    if (sim) {
      user = std::make_shared<CalibrationUser>(cfg);
      device::SimulatedSpidarParams p;
      p.seed = a->backend.seed;
      p.fixed_step_s = 1e-3;
      if (a->jig > 0) {
        // A jig clamps the fingertip cap at its point (a stiff mount, critically damped); at the
        // pole the user holds it by hand, so the strings' minimum tension pulls it off by a few
        // millimetres (the paper: about 5 mm per finger).
        p.impedance.stiffness = 20000;
        p.impedance.damping = 2 * std::sqrt(p.impedance.stiffness * p.impedance.mass);
      }
      dev = std::make_unique<device::SimulatedSpidar>(cfg, p, user);
    } else {
      dev = make_backend(a->backend, cfg);
    }
    if (auto st = dev->open(); !st) throw UsageError("device: " + st.error().message);
    dev->clear_safe_state();
    std::vector<std::int32_t> commands(cfg.string_count(), cfg.command_range().min);  // taut strings
    const std::int64_t t0 = core::monotonic_ns();
    std::uint64_t cycle = 0;
    auto now_s = [&] { return sim ? static_cast<double>(cycle) * 1e-3 : core::ns_to_s(core::monotonic_ns() - t0); };
    StabilityParams sp;
    sp.hold_s = a->hold_s;
    sp.tolerance_m = a->tolerance_mm * 1e-3;
    sp.near_m = a->near_mm > 0 ? a->near_mm * 1e-3 : 1e9;

    nlohmann::json report;
    report["method"] = a->jig > 0 ? "multi-point jig" : "pole";
    report["config"] = path;
    if (sim) report["simulated_fingertip"] = a->jig > 0 ? "clamped in the jig" : "held at the pole by hand";
    std::ifstream in(path);
    std::stringstream text_ss;
    text_ss << in.rdbuf();
    std::string text = text_ss.str();
    const std::string note = std::string(a->jig > 0 ? "multi-point jig" : "pole") + " calibration (" +
                             (sim ? "simulated device" : "device " + a->backend.port) + ")";

    for (int f : fingers) {
      const strings::FingerConfig& fc = cfg.fingers[f];
      std::vector<strings::JigSample> samples;
      std::vector<std::int64_t> pole_counts;
      for (std::size_t k = 0; k < targets.size(); ++k) {
        const Vec3& target = targets[k];
        std::cerr << fc.name << ": " << (a->jig > 0 ? "place the fingertip cap on jig point " + std::to_string(k + 1) + "/" + std::to_string(targets.size())
                                                     : std::string("touch the pole tip with the fingertip cap"))
                  << " and hold still\n";
        const double t_step = now_s();
        if (user) user->activate(f, target, t_step);
        StabilityCheck check(fc, target, sp);
        double next_note = t_step + 0.25;
        device::EncoderReading reading;
        while (!check.ready()) {
          if (auto st = dev->read(reading); !st) {
            dev->close();
            throw UsageError("device: " + st.error().message);
          }
          (void)dev->write(commands);
          ++cycle;
          const double t = now_s();
          check.update(t, finger_counts(cfg, f, reading));
          if (t >= next_note) {
            next_note += 0.25;
            std::cerr << "  " << (check.distance_m() > sp.near_m ? "not at the target yet" : check.held_s() > 0 ? "holding" : "moving")
                      << ": " << std::lround(check.distance_m() * 1e3) << " mm away by the present calibration, held "
                      << std::lround(check.held_s() * 1e3) << "/" << std::lround(sp.hold_s * 1e3) << " ms\n";
          }
          if (t - t_step > a->timeout_s) {
            dev->close();
            throw UsageError(fc.name + ": the fingertip did not hold still near the target within " +
                             std::to_string(static_cast<int>(a->timeout_s)) + " s (last: " +
                             std::to_string(check.distance_m() * 1e3) + " mm away, strings moving " +
                             std::to_string(check.spread_m() * 1e3) + " mm)");
          }
          if (!sim) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        const auto s = check.sample();
        std::cerr << "  sampled after holding " << sp.hold_s << " s\n";
        if (a->jig > 0) samples.push_back({target, s});
        else pole_counts = s;
      }
      nlohmann::json jf;
      jf["finger"] = fc.name;
      std::vector<strings::EncoderChannel> channels;
      if (a->jig > 0) {
        auto fit = strings::fit_multipoint(fc.geometry, samples);
        if (!fit) throw UsageError(fc.name + ": " + fit.error().message);
        for (const auto& sf : *fit) {
          channels.push_back(sf.channel);
          jf["residual_rms_mm"].push_back(sf.residual_rms * 1e3);
        }
      } else {
        auto ch = strings::pole_calibrate(fc.geometry, fc.channels, pole_counts, cfg.p_W_centre);
        if (!ch) throw UsageError(fc.name + ": " + ch.error().message);
        channels = *ch;
        jf["pole_error_before_mm"] = pole_error_mm(fc, fc.channels, pole_counts, cfg.p_W_centre);
        jf["pole_error_after_mm"] = pole_error_mm(fc, channels, pole_counts, cfg.p_W_centre);
      }
      for (std::size_t i = 0; i < channels.size(); ++i) {
        jf["length_at_zero_before"].push_back(fc.channels[i].length_at_zero);
        jf["length_at_zero"].push_back(channels[i].length_at_zero);
        jf["metres_per_count"].push_back(channels[i].metres_per_count);
        jf["signs"].push_back(channels[i].sign);
      }
      if (sim) {
        // The simulated device's true channels: counters zeroed with the fingertips at the centre.
        std::vector<strings::EncoderChannel> truth = fc.channels;
        for (int i = 0; i < fc.geometry.n; ++i)
          truth[i].length_at_zero = (fc.geometry.p_WA[i] - cfg.p_W_centre).norm();
        const auto test = strings::jig_grid(cfg.p_W_centre, 0.05, 3);
        if (auto e = strings::position_error_rms(fc.geometry, truth, fc.channels, test)) jf["sim_position_error_before_mm"] = *e * 1e3;
        if (auto e = strings::position_error_rms(fc.geometry, truth, channels, test)) jf["sim_position_error_after_mm"] = *e * 1e3;
      }
      text = with_finger_channels(text, path, fc.name, channels, a->jig > 0, note);
      report["fingers"].push_back(jf);
    }
    dev->close();
    // The measurement is printed before the config is touched: should the write fail (a
    // read-only folder, a full disk), the result is on stdout and nothing is lost.
    report["dry_run"] = a->dry_run;
    require_finite_json(report, "calibrate-strings report");
    std::cout << report.dump(2) << "\n" << std::flush;
    if (a->dry_run) return 0;
    try {
      const std::string backup = write_config_with_backup(path, text);
      std::cerr << "wrote " << path << " (previous version: " << backup << ")\n";
    } catch (const SpidarError& e) {
      throw UsageError(std::string(e.what()) + " (the calibration is printed above; the config is unchanged)");
    }
    return 0;
  };
}

}  // namespace spidar::app
