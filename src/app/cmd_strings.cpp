// spidar-mr check-config | position | tension: the string maths from the command line.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "spidar/session/json_text.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "spidar/core/config.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/hand/hand_config.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/registration/shape_estimator.hpp"
#include "spidar/session/live_config.hpp"
#include "spidar/vision/camera_config.hpp"
#include "spidar/vision/vision_config.hpp"
#include "spidar/device/workspace.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::app {
namespace {

/// The largest force the CLI takes [N]: far above any string drive (SPIDAR-8's saturates at
/// 17 N per string); beyond it an input is a typo, not a request.
constexpr double kMaxForceN = 1000.0;
/// String lengths above this multiple of the farthest fulcrum from the frame centre are refused.
constexpr double kMaxLengthFactor = 100.0;

std::string finger_label(const strings::DeviceConfig& cfg, int f) {
  return "finger " + std::to_string(f) + " (" + cfg.fingers[f].name + ")";
}

std::string num(double x) {
  std::ostringstream os;
  os << x;
  return os.str();
}

/// Three finite numbers, none subnormal (1e-310 is in range, but no value a user means: a typo for
/// 1e-3 or so), as a vector; else a UsageError naming the option and the number.
Vec3 vec3_arg(const std::vector<double>& v, const char* name) {
  for (double x : v) {
    if (!std::isfinite(x)) {
      throw UsageError(std::string(name) + ": expected finite numbers, got " + std::to_string(x));
    }
    if (std::fpclassify(x) == FP_SUBNORMAL) {
      throw UsageError(std::string(name) + ": expected numbers of ordinary size, got " + num(x) +
                       " (a subnormal number, effectively 0: write 0 if 0 is meant)");
    }
  }
  return {v[0], v[1], v[2]};
}

/// UsageError unless `p_W` lies in the device's workspace (the fulcrums' box grown by the servo
/// loop's margin: a solved point outside it means lengths no fingertip in the frame can have).
void require_in_workspace(const strings::DeviceConfig& cfg, const Vec3& p_W, const std::string& what,
                          const std::string& expected) {
  const double margin = device::ServoConfig{}.workspace_margin_m;
  const auto ws = device::device_workspace(cfg, margin);
  const auto ex = device::workspace_excess(ws, {p_W.x(), p_W.y(), p_W.z()});
  if (ex.axis < 0 && ex.distance_m == 0) return;
  const char* axis = ex.axis == 0 ? "x" : ex.axis == 1 ? "y" : ex.axis == 2 ? "z" : "?";
  throw UsageError(what + " (" + num(p_W.x()) + ", " + num(p_W.y()) + ", " + num(p_W.z()) + ") m, " +
                   num(ex.distance_m) + " m outside the device's workspace along " + axis + " (face at " +
                   num(ex.limit_m) + " m); expected " + expected + " within " + num(margin) +
                   " m of the box of " + cfg.source + "'s fulcrums");
}

/// What position and tension take first: the device config and a finger.
struct FingerArgs {
  std::string config = "configs/spidar8.yaml";
  std::string finger;
};

void add_finger_options(CLI::App& cmd, FingerArgs& a) {
  cmd.add_option("--config", a.config, "device config (YAML)")->capture_default_str();
  cmd.add_option("--finger", a.finger, "finger index or name")->required();
}

}  // namespace

Action add_check_config(CLI::App& app) {
  auto* cmd = app.add_subcommand("check-config",
                                 "Validate any spidar-mr config (device, camera, vision, registration, hands, "
                                 "live session: told apart by its top-level keys) and summarise it");
  auto file = std::make_shared<std::string>();
  cmd->add_option("file", *file, "config (YAML)")->required();
  return [file] {
    // The kind of config, by its top-level keys (configs/*.yaml); a device config otherwise.
    const auto root = core::ConfigNode::LoadFile(*file);
    const auto keys = root.is_map() ? root.keys() : std::vector<std::string>{};
    auto has = [&](const char* k) { return std::find(keys.begin(), keys.end(), k) != keys.end(); };
    std::ostringstream os;
    os << *file << ": ok: ";
    if (has("device") && has("camera")) {
      const auto live = session::load_live_config(*file, false);
      os << "live session config (" << live.backend << " device, " << live.camera_source << " camera, compositor "
         << live.compositor << ")";
    } else if (has("camera")) {
      const auto cam = vision::load_camera_file(*file).camera;  // a lens that folds the image is refused
      os << "camera " << cam.width() << "x" << cam.height() << ", fx " << num(cam.intrinsics().fx) << " px";
    } else if (has("chroma_key") || has("bracelet")) {
      (void)vision::load_vision_config(*file);
      os << "vision settings (chroma key, bracelet)";
    } else if (has("registration") || has("personalisation")) {
      if (has("registration")) (void)registration::parse_registration_params(root["registration"]);
      bool personalise = false;
      if (has("personalisation")) (void)registration::parse_shape_estimator_params(root["personalisation"], &personalise);
      os << "registration settings" << (has("personalisation") ? std::string(", personalisation ") + (personalise ? "on" : "off") : "");
    } else if (has("hands")) {
      const auto hands = hand::load_hand_profiles(*file);
      os << hands.profiles.size() << " hand profile(s):";
      for (const auto& p : hands.profiles)
        os << " " << p.name << " (" << num(1e3 * p.dimensions.length) << " x " << num(1e3 * p.dimensions.width) << " mm)";
    } else {
      const auto cfg = strings::load_device_config(*file);
      const auto lim = cfg.effective_limits();
      os << cfg.name << ", " << cfg.fingers.size() << " fingers, "
         << cfg.string_count() << " strings, tension " << cfg.tension.t_min << "-"
         << cfg.tension.t_max << " N (drive delivers " << lim.t_min << "-" << lim.t_max << " N)";
    }
    std::cout << os.str() << "\n";
    return 0;
  };
}

Action add_position(CLI::App& app) {
  auto* cmd = app.add_subcommand("position", "Fingertip position from string lengths (JSON)");
  struct Args : FingerArgs {
    std::vector<double> lengths;
  };
  auto a = std::make_shared<Args>();
  add_finger_options(*cmd, *a);
  cmd->add_option("--lengths", a->lengths, "string lengths [m], one per string")
      ->required()
      ->expected(1, -1);
  return [a] {
    const auto cfg = strings::load_device_config(resolve_data_path(a->config));
    const int f = find_finger(cfg, a->finger);
    const auto& g = cfg.fingers[f].geometry;
    if (static_cast<int>(a->lengths.size()) != g.n) {
      throw UsageError("--lengths: finger " + std::to_string(f) + " (" + cfg.fingers[f].name +
                       ") has " + std::to_string(g.n) + " strings; got " +
                       std::to_string(a->lengths.size()) + " lengths");
    }
    double reach = 0;  // the farthest fulcrum from the frame centre [m]
    for (int i = 0; i < g.n; ++i) reach = std::max(reach, (g.p_WA[i] - cfg.p_W_centre).norm());
    const double max_length = kMaxLengthFactor * reach;
    for (int i = 0; i < g.n; ++i) {
      const double l = a->lengths[i];
      if (!(l > 0 && l <= max_length)) {
        throw UsageError("--lengths: " + finger_label(cfg, f) + ": string " + std::to_string(i) + ": length " +
                         num(l) + " m; expected more than 0 and at most " + num(max_length) + " m (" +
                         num(kMaxLengthFactor) + " x its farthest fulcrum from the frame centre)");
      }
    }
    auto est = strings::solve_position(g, a->lengths);
    if (!est) {
      throw UsageError("--lengths: finger " + std::to_string(f) + " (" + cfg.fingers[f].name +
                       "): " + est.error().message);
    }
    require_in_workspace(cfg, est->p_WF, "--lengths: " + finger_label(cfg, f) + ": the lengths put the fingertip at",
                         "the lengths of a point");
    nlohmann::json j = {{"finger", f},
                        {"position", to_json(est->p_WF)},
                        {"consistent", est->consistent},
                        {"residual", est->residual}};
    require_finite_json(j, "position output");
    std::cout << session::json_text(j) << "\n";
    return 0;
  };
}

Action add_tension(CLI::App& app) {
  auto* cmd = app.add_subcommand("tension", "String tensions displaying a force (JSON)");
  struct Args : FingerArgs {
    std::vector<double> position, force;
  };
  auto a = std::make_shared<Args>();
  add_finger_options(*cmd, *a);
  cmd->add_option("--position", a->position, "fingertip position X Y Z [m]")
      ->required()
      ->expected(3);
  cmd->add_option("--force", a->force, "desired force FX FY FZ [N]")->required()->expected(3);
  return [a] {
    const auto cfg = strings::load_device_config(resolve_data_path(a->config));
    const int f = find_finger(cfg, a->finger);
    const Vec3 p = vec3_arg(a->position, "--position");
    const Vec3 force = vec3_arg(a->force, "--force");
    require_in_workspace(cfg, p, "--position: " + finger_label(cfg, f) + ":", "a point");
    if (!(force.stableNorm() <= kMaxForceN)) {  // stableNorm: |(1e308, 0, 0)| is 1e308, not inf
      throw UsageError("--force: " + num(force.stableNorm()) + " N; expected a force of at most " + num(kMaxForceN) + " N");
    }
    auto sol = strings::solve_tensions(cfg.fingers[f].geometry, p, force, cfg.effective_limits());
    if (!sol) {
      throw UsageError("finger " + std::to_string(f) + " (" + cfg.fingers[f].name +
                       "): " + sol.error().message);
    }
    nlohmann::json t = nlohmann::json::array();
    for (int i = 0; i < sol->t.size(); ++i) t.push_back(sol->t[i]);
    nlohmann::json j = {{"finger", f},
                        {"tensions", t},
                        {"force", to_json(sol->f_displayed)},
                        {"reachable", sol->reachable}};
    require_finite_json(j, "tension output");
    std::cout << session::json_text(j) << "\n";
    return 0;
  };
}

}  // namespace spidar::app
