// spidar-mr demo (haptic scenario): the simulated SPIDAR-8 with a scripted user. The left hand
// grasps and lifts the Rubik's cube, the right hand turns its top layer by 90°, all through the
// real pipeline: simulated encoders → servo loop (positions, tensions, commands) ↔ physics in its
// own thread (proxies, coupling, contacts) with passivity control per finger.
#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "spidar/session/json_text.hpp"
#include "spidar/session/data_path.hpp"
#include "spidar/session/finite_json.hpp"
#include "spidar/session/scenarios.hpp"
#include "spidar/core/atomic_write.hpp"
#include "spidar/core/clock.hpp"
#include "spidar/core/units.hpp"
#include "spidar/device/servo_loop.hpp"
#include "spidar/device/simulated_spidar.hpp"
#include "spidar/physics/rubiks_cube.hpp"
#include "spidar/session/cube_monitor.hpp"
#include "spidar/session/haptic_side.hpp"
#include "spidar/session/stats_json.hpp"
#include "spidar/sim/scripted_grasp.hpp"

namespace spidar::session {

device::ServoStats run_haptic_scenario(const ScenarioOptions& o, std::ostream& out) {
  namespace fs = std::filesystem;
  const auto cfg = strings::load_device_config(resolve_data_path(o.config));
  const std::string scene = resolve_data_path(o.scene);
  physics::WorldParams wp;
  auto world_r = physics::World::Load(scene, wp);
  if (!world_r) throw SpidarError("--scene: " + world_r.error().message);
  auto world = std::move(world_r).value();
  auto cube_r = physics::RubiksCube::Attach(*world);
  if (!cube_r) throw SpidarError("--scene: the haptic demo needs a Rubik's cube scene: " + cube_r.error().message);
  auto cube = std::move(cube_r).value();
  fs::create_directories(o.out);

  const Pose X_cube0 = cube.core_pose();
  sim::RubiksScriptParams sp;
  sp.p_W_cube = X_cube0.p;
  sp.proxy_radius = wp.proxy.radius;
  auto script = std::make_shared<sim::RubiksScript>(sp);
  // --seconds 0: the script's own length; otherwise the run stops there (a short run is cut).
  const double seconds = o.seconds > 0 ? o.seconds : sp.duration;

  device::SimulatedSpidarParams dp;
  dp.seed = o.seed;
  device::SimulatedSpidar dev(cfg, dp, script);

  HapticSideParams hp;
  hp.servo.rate_hz = o.rate_hz;
  hp.servo.idle_spin = o.idle_spin;
  hp.servo.force_timeout_s = 0.05;
  const device::ServoConfig& servo = hp.servo;
  HapticSide haptic(dev, cfg, *world, wp.coupling, hp);
  core::Latest<CubeStatus> cube_status;
  haptic.set_before_step([&](physics::World& w) {
    CubeStatus s;
    s.t_s = w.time();
    s.present = true;
    s.lift = cube.core_pose().p.z() - X_cube0.p.z();
    s.u_angle = cube.face_angle('U');
    s.u_misalign = cube.face_misalignment('U');
    s.contacts = w.contact_count();
    cube_status.publish(s);
  });
  device::ServoLoop& loop = haptic.loop();

  out << "spidar-mr demo: haptic Rubik's cube on a simulated " << cfg.name << "\n  scene "
            << scene << ", servo " << servo.rate_hz << " Hz, physics in its own thread at "
            << 1.0 / world->timestep() << " Hz, coupling " << wp.coupling.stiffness << " N/m\n\n";
  haptic.start();

  // Record every servo sample from the lock-free ring while the scenario runs.
  std::vector<device::FingertipSample> trace;
  trace.reserve(static_cast<std::size_t>(seconds * servo.rate_hz * 1.1) + 1024);
  std::vector<device::FingertipSample> buf(1023);
  std::uint64_t next_cycle = 0;
  double lift_max = 0, angle_max = 0;
  const std::int64_t t0 = core::monotonic_ns();
  double next_print = 0;
  while (loop.running()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const std::size_t n = loop.newest_samples(buf.data(), buf.size());
    for (std::size_t k = n; k-- > 0;) {
      if (buf[k].cycle >= next_cycle) {
        trace.push_back(buf[k]);
        next_cycle = buf[k].cycle + 1;
      }
    }
    const double t = core::ns_to_s(core::monotonic_ns() - t0);
    if (auto s = cube_status.read()) {
      lift_max = std::max(lift_max, s->lift);
      angle_max = std::max(angle_max, s->u_angle);
      if (t >= next_print) {
        out << std::fixed << std::setprecision(1) << "  t=" << std::setw(4) << t << " s  "
                  << std::left << std::setw(19) << sim::RubiksScript::phase(t) << std::right
                  << " lift " << std::setw(5) << s->lift * 1e3 << " mm   top layer "
                  << std::setw(6) << units::rad_to_deg(s->u_angle) << " deg   contacts "
                  << s->contacts << "   faults " << device::fault_names(loop.faults()) << "\n";
        next_print += 0.5;
      }
    }
    if (t >= seconds) break;
  }
  haptic.stop();

  // Summary.
  const auto ss = loop.stats();
  const auto ps = haptic.physics().stats();
  const auto hs = haptic.bridge().stats();
  const auto final_status = cube_status.read().value_or(CubeStatus{});
  std::vector<double> fmax(cfg.fingers.size(), 0.0);
  double jump_max = 0;
  for (std::size_t k = 0; k < trace.size(); ++k) {
    for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
      const Vec3 F = device::fingertip_force(trace[k], static_cast<int>(f));
      fmax[f] = std::max(fmax[f], F.norm());
      if (k > 0 && trace[k].cycle == trace[k - 1].cycle + 1) {
        const Vec3 Fp = device::fingertip_force(trace[k - 1], static_cast<int>(f));
        jump_max = std::max(jump_max, (F - Fp).norm());
      }
    }
  }
  out << "\nresult:\n" << std::fixed << std::setprecision(2)
            << "  cube lifted           " << lift_max * 1e3 << " mm (max)\n"
            << "  top layer turned      " << units::rad_to_deg(angle_max) << " deg (max), final "
            << units::rad_to_deg(final_status.u_angle) << " deg, "
            << units::rad_to_deg(final_status.u_misalign) << " deg from a click\n"
            << "  cube solved           " << (cube.is_solved() ? "yes" : "no (a layer is turned)")
            << "\n  servo                 " << ss.rate_hz << " Hz, jitter p50/p99/max "
            << ss.jitter_p50_us << "/" << ss.jitter_p99_us << "/" << ss.jitter_max_us
            << " us, overruns " << ss.overruns << ", faults " << device::fault_names(ss.faults)
            << "\n  physics               " << ps.rate_hz << " Hz, step median/p99 "
            << ps.step_ms_median << "/" << ps.step_ms_p99 << " ms\n"
            << "  largest force change between servo cycles " << jump_max << " N\n"
            << "  per finger            max |F| [N]   energy observer: min E [mJ], damping added [mJ], active cycles\n";
  nlohmann::json fingers = nlohmann::json::array();
  for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
    const auto& port = hs.ports[f];
    out << "    " << std::left << std::setw(14) << cfg.fingers[f].name << std::right
              << std::setw(12) << fmax[f] << std::setw(16) << port.min_energy * 1e3 << std::setw(12)
              << port.dissipated * 1e3 << std::setw(12) << port.active_steps << "\n";
    fingers.push_back({{"name", cfg.fingers[f].name},
                       {"force_max_n", fmax[f]},
                       {"energy_min_mj", port.min_energy * 1e3},
                       {"energy_dissipated_mj", port.dissipated * 1e3},
                       {"passivity_active_cycles", port.active_steps}});
  }
  std::ostringstream csv;  // written whole (write_file_atomic) below, never cut mid-row
  csv << "t";
  for (const auto& f : cfg.fingers) {
    for (const char* q : {"x", "y", "z", "fx", "fy", "fz"}) csv << ',' << f.name << '_' << q;
  }
  csv << '\n';
  for (const auto& s : trace) {
    csv << core::ns_to_s(s.t_ns - trace.front().t_ns);
    for (std::size_t f = 0; f < cfg.fingers.size(); ++f) {
      for (int k = 0; k < 3; ++k) csv << ',' << s.p_W[f][k];
      for (int k = 0; k < 3; ++k) csv << ',' << s.f_W[f][k];
    }
    csv << '\n';
  }
  core::write_file_atomic((fs::path(o.out) / "haptic_trace.csv").string(), csv.str());
  nlohmann::json report = {
      {"scenario", "haptic"},
      {"scene", scene},
      {"seconds", seconds},
      {"cube",
       {{"lift_max_mm", lift_max * 1e3},
        {"top_layer_max_deg", units::rad_to_deg(angle_max)},
        {"top_layer_final_deg", units::rad_to_deg(final_status.u_angle)},
        {"top_layer_misalignment_deg", units::rad_to_deg(final_status.u_misalign)},
        {"solved", cube.is_solved()},
        {"facelets", cube.facelets()}}},
      {"haptic", [&] {
         nlohmann::json h = servo_timing_json(ss);
         h.update({{"faults", device::fault_names(ss.faults)},
                   {"fault_message", ss.fault_message},
                   {"force_jump_max_n", jump_max}});
         return h;
       }()},
      {"physics",
       {{"rate_hz", ps.rate_hz},
        {"step_ms_median", ps.step_ms_median},
        {"step_ms_p99", ps.step_ms_p99},
        {"steps", ps.steps},
        {"memory", physics_memory_json(ps.memory)}}},
      {"fingers", fingers}};
  require_finite_json(report, (fs::path(o.out) / "report.json").string());
  core::write_file_atomic((fs::path(o.out) / "report.json").string(), json_text(report, 2) + "\n");
  out << "wrote " << (fs::path(o.out) / "haptic_trace.csv").string() << " and "
            << (fs::path(o.out) / "report.json").string() << "\n";
  return ss;
}

}  // namespace spidar::session
