// spidar-mr calibrate-strings: pole calibration finger by finger (the paper's), or the multi-point
// jig, with a stability check before each sample; the results go back into the device config,
// whose previous version is kept beside it (file.yaml.bak-YYYYmmdd-HHMMSS).
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "device_backends.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/config.hpp"
#include "spidar/core/file_read.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/device/string_calibration.hpp"
#include "spidar/strings/calibration.hpp"
#include "spidar/strings/device_config_write.hpp"

namespace spidar::app {

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
  CLI::Option* spacing =
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
  return [a, spacing] {
    if (!(a->jig == 0 || (a->jig >= 2 && a->jig <= 5)))
      throw UsageError("--jig: expected 0 (pole) or 2 to 5, got " + std::to_string(a->jig));
    if (a->jig == 0) refuse_given(spacing, "to a jig (--jig 2 to 5), not to the pole calibration (--jig 0)");
    require_range(a->jig_spacing, 0.005, 0.2, "--jig-spacing", "m");
    require_range(a->hold_s, 0.05, 10, "--hold", "s");
    require_above(a->tolerance_mm, 0, 20, "--tolerance", "mm");
    require_range(a->near_mm, 0, 1000, "--near", "mm");
    require_above(a->timeout_s, 0, 600, "--timeout", "s");
    const std::string path = resolve_data_path(a->backend.config);
    const strings::DeviceConfig cfg = strings::load_device_config(path);
    std::vector<int> fingers;
    if (a->fingers.empty()) {
      for (int f = 0; f < static_cast<int>(cfg.fingers.size()); ++f) fingers.push_back(f);
    } else {
      fingers = parse_finger_list(cfg, a->fingers, "--fingers");
    }
    // The device: the simulated SPIDAR with a simulated user who follows the guidance, stepped
    // 1 ms per reading (simulated time, as fast as it computes), or the hardware in real time.
    const bool sim = a->backend.backend == "sim";
    std::shared_ptr<device::CalibrationUser> user;
    std::unique_ptr<device::Device> dev;
    if (sim) {
      user = std::make_shared<device::CalibrationUser>(cfg);
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
    const std::int64_t t0 = core::monotonic_ns();
    std::uint64_t cycle = 0;
    device::CalibrationClock clock;
    clock.now_s = [&] { return sim ? static_cast<double>(cycle) * 1e-3 : core::ns_to_s(core::monotonic_ns() - t0); };
    clock.pace = [&] {
      ++cycle;
      if (!sim) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    };
    device::StringCalibrationParams cp;
    cp.fingers = fingers;
    cp.jig = a->jig;
    cp.jig_spacing_m = a->jig_spacing;
    cp.stability.hold_s = a->hold_s;
    cp.stability.tolerance_m = a->tolerance_mm * 1e-3;
    cp.stability.near_m = a->near_mm > 0 ? a->near_mm * 1e-3 : 1e9;
    cp.timeout_s = a->timeout_s;
    auto on_target = [&](int f, const Vec3& target, double t_s) {
      if (user) user->activate(f, target, t_s);
    };
    const auto result = device::calibrate_strings(
        *dev, cfg, cp, clock, [](const std::string& line) { std::cerr << line << "\n"; }, on_target);
    dev->close();
    if (!result) throw UsageError(result.error().message);

    nlohmann::json report;
    report["method"] = a->jig > 0 ? "multi-point jig" : "pole";
    report["config"] = path;
    if (sim) report["simulated_fingertip"] = a->jig > 0 ? "clamped in the jig" : "held at the pole by hand";
    std::string text = core::read_file_bounded(path, core::kMaxConfigFileBytes, "a config file");
    const std::string note = std::string(a->jig > 0 ? "multi-point jig" : "pole") + " calibration (" +
                             (sim ? "simulated device" : "device " + a->backend.port) + ")";
    for (const device::FingerCalibration& fr : *result) {
      const strings::FingerConfig& fc = cfg.fingers[static_cast<std::size_t>(fr.finger)];
      const auto& channels = fr.channels;
      nlohmann::json jf;
      jf["finger"] = fc.name;
      for (double r : fr.residual_rms_m) jf["residual_rms_mm"].push_back(r * 1e3);
      if (fr.pole_error_before_m) jf["pole_error_before_mm"] = *fr.pole_error_before_m * 1e3;
      if (fr.pole_error_after_m) jf["pole_error_after_mm"] = *fr.pole_error_after_m * 1e3;
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
      text = strings::with_finger_channels(text, path, fc.name, channels, a->jig > 0, note);
      report["fingers"].push_back(jf);
    }
    // The measurement is printed before the config is touched: should the write fail (a
    // read-only folder, a full disk), the result is on stdout and nothing is lost.
    report["dry_run"] = a->dry_run;
    require_finite_json(report, "calibrate-strings report");
    std::cout << session::json_text(report, 2) << "\n" << std::flush;
    if (a->dry_run) return 0;
    try {
      const std::string backup = strings::write_device_config(path, text);
      std::cerr << "wrote " << path << " (previous version: " << backup << ")\n";
    } catch (const SpidarError& e) {
      throw UsageError(std::string(e.what()) + " (the calibration is printed above; the config is unchanged)");
    }
    return 0;
  };
}

}  // namespace spidar::app
