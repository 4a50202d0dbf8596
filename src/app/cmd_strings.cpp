// spidar-mr check-config | position | tension: the string maths from the command line.
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "spidar/strings/position.hpp"
#include "spidar/strings/tension.hpp"

namespace spidar::app {
namespace {

Vec3 vec3_arg(const std::vector<double>& v, const char* name) {
  for (double x : v) {
    if (!std::isfinite(x)) {
      throw UsageError(std::string(name) + ": expected finite numbers, got " + std::to_string(x));
    }
  }
  return {v[0], v[1], v[2]};
}

}  // namespace

Action add_check_config(CLI::App& app) {
  auto* cmd = app.add_subcommand("check-config", "Validate a device config and summarise it");
  auto file = std::make_shared<std::string>();
  cmd->add_option("file", *file, "device config (YAML)")->required();
  return [file] {
    const auto cfg = strings::load_device_config(*file);
    const auto lim = cfg.effective_limits();
    std::ostringstream os;
    os << *file << ": ok: " << cfg.name << ", " << cfg.fingers.size() << " fingers, "
       << cfg.string_count() << " strings, tension " << cfg.tension.t_min << "-"
       << cfg.tension.t_max << " N (drive delivers " << lim.t_min << "-" << lim.t_max << " N)";
    std::cout << os.str() << "\n";
    return 0;
  };
}

Action add_position(CLI::App& app) {
  auto* cmd = app.add_subcommand("position", "Fingertip position from string lengths (JSON)");
  struct Args {
    std::string config = "configs/spidar8.yaml";
    std::string finger;
    std::vector<double> lengths;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--config", a->config, "device config (YAML)")->capture_default_str();
  cmd->add_option("--finger", a->finger, "finger index or name")->required();
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
    auto est = strings::solve_position(g, a->lengths);
    if (!est) {
      throw UsageError("--lengths: finger " + std::to_string(f) + " (" + cfg.fingers[f].name +
                       "): " + est.error().message);
    }
    nlohmann::json j = {{"finger", f},
                        {"position", to_json(est->p_WF)},
                        {"consistent", est->consistent},
                        {"residual", est->residual}};
    std::cout << j.dump() << "\n";
    return 0;
  };
}

Action add_tension(CLI::App& app) {
  auto* cmd = app.add_subcommand("tension", "String tensions displaying a force (JSON)");
  struct Args {
    std::string config = "configs/spidar8.yaml";
    std::string finger;
    std::vector<double> position, force;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--config", a->config, "device config (YAML)")->capture_default_str();
  cmd->add_option("--finger", a->finger, "finger index or name")->required();
  cmd->add_option("--position", a->position, "fingertip position X Y Z [m]")
      ->required()
      ->expected(3);
  cmd->add_option("--force", a->force, "desired force FX FY FZ [N]")->required()->expected(3);
  return [a] {
    const auto cfg = strings::load_device_config(resolve_data_path(a->config));
    const int f = find_finger(cfg, a->finger);
    const Vec3 p = vec3_arg(a->position, "--position");
    const Vec3 force = vec3_arg(a->force, "--force");
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
    std::cout << j.dump() << "\n";
    return 0;
  };
}

}  // namespace spidar::app
