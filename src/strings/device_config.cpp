#include "spidar/strings/device_config.hpp"

#include <algorithm>
#include <sstream>

#include "spidar/strings/convex_hull.hpp"

namespace spidar::strings {
namespace {

/// An encoder's resolution [m per count]: from a nanometre to a centimetre.
constexpr double kMinMetresPerCount = 1e-9;
constexpr double kMaxMetresPerCount = 1e-2;

std::vector<double> per_string(const core::ConfigNode& finger, std::string_view key, int n,
                               double fallback) {
  auto node = finger.find(key);
  if (!node) return std::vector<double>(n, fallback);
  auto v = node->as_doubles();
  if (static_cast<int>(v.size()) != n) {
    node->fail("expected " + std::to_string(n) + " numbers (one per string), got " +
               std::to_string(v.size()));
  }
  return v;
}

FingerConfig parse_finger(const core::ConfigNode& node, const DeviceConfig& dev,
                          double default_mpc) {
  node.expect_keys({"name", "hand", "unit", "fulcrums", "signs", "metres_per_count",
                    "length_at_zero"});
  FingerConfig f;
  f.name = core::require_non_blank(node["name"], "finger name");
  if (auto hand = node.find("hand")) {
    f.hand = hand->as_string();
    if (f.hand != "left" && f.hand != "right") hand->fail("expected 'left' or 'right'");
  }
  if (node.has("unit")) {
    const std::int64_t unit = node["unit"].as_int();
    if (unit < 0 || unit >= kMaxConfigFingers) {
      node["unit"].fail("expected a unit number 0.." + std::to_string(kMaxConfigFingers - 1) +
                        " (one per fingertip), got " + std::to_string(unit));
    }
    f.unit = static_cast<int>(unit);
  }
  const auto fulcrums = node["fulcrums"];
  std::vector<Vec3> p_WA;
  for (std::size_t i = 0; i < fulcrums.size(); ++i) p_WA.push_back(fulcrums.at(i).as_vec3());
  auto geometry = make_point_geometry(p_WA, dev.p_W_centre);
  if (!geometry) fulcrums.fail(geometry.error().message);
  f.geometry = *geometry;
  const int n = f.geometry.n;

  const auto signs = per_string(node, "signs", n, 1.0);
  const auto mpc = per_string(node, "metres_per_count", n, default_mpc);
  std::vector<double> l0(n);
  for (int i = 0; i < n; ++i) l0[i] = (p_WA[i] - dev.p_W_centre).norm();
  if (node.has("length_at_zero")) l0 = per_string(node, "length_at_zero", n, 0.0);
  for (int i = 0; i < n; ++i) {
    if (signs[i] != 1.0 && signs[i] != -1.0) {
      node["signs"].at(i).fail("expected +1 or -1");
    }
    // The same range as the encoder's default (parse_device_config), which a finger without its
    // own values takes and which was checked at its own key.
    if (node.has("metres_per_count"))
      core::require_in_range(node["metres_per_count"].at(i), mpc[i], kMinMetresPerCount, kMaxMetresPerCount, "m");
    f.channels.push_back({static_cast<int>(signs[i]), mpc[i], l0[i]});
  }
  return f;
}

}  // namespace

int DeviceConfig::string_count() const {
  int n = 0;
  for (const auto& f : fingers) n += f.geometry.n;
  return n;
}

int DeviceConfig::first_string(int finger) const {
  int n = 0;
  for (int f = 0; f < finger; ++f) n += fingers[static_cast<std::size_t>(f)].geometry.n;
  return n;
}

TensionLimits DeviceConfig::effective_limits() const {
  return {std::max(tension.t_min, min_drive_tension(motor)),
          std::min(tension.t_max, max_drive_tension(motor))};
}

DeviceConfig::CommandRange DeviceConfig::command_range() const {
  const auto lim = effective_limits();
  return {tension_to_command(motor, lim.t_min).dac, tension_to_command(motor, lim.t_max).dac};
}

DeviceConfig parse_device_config(const core::ConfigNode& root) {
  root.expect_keys({"name", "frame_centre", "encoder", "motor", "tension", "fingers"});
  DeviceConfig dev;
  dev.source = root.file();
  dev.name = core::require_non_blank(root["name"], "device name");
  if (auto c = root.find("frame_centre")) dev.p_W_centre = c->as_vec3();

  const auto enc = root["encoder"];
  enc.expect_keys({"metres_per_count", "counter_bits"});
  const auto mpc_node = enc["metres_per_count"];
  const double mpc = core::require_in_range(mpc_node, mpc_node.as_double(), kMinMetresPerCount, kMaxMetresPerCount, "m");
  if (enc.has("counter_bits")) dev.counter_bits = static_cast<int>(core::require_int_in_range(enc["counter_bits"], 8, 62));

  const auto motor = root["motor"];
  motor.expect_keys({"pulley_radius", "torque_constant", "amplifier_gain", "dac_bits",
                     "dac_v_min", "dac_v_max"});
  auto positive = [&](const char* key) {
    const auto n = motor[key];
    const double v = n.as_double();
    if (!(v > 0.0)) n.fail("expected a positive number, got " + std::to_string(v));
    return v;
  };
  dev.motor.pulley_radius = positive("pulley_radius");
  dev.motor.torque_constant = positive("torque_constant");
  dev.motor.amplifier_gain = positive("amplifier_gain");
  dev.motor.dac_bits = static_cast<int>(core::require_int_in_range(motor["dac_bits"], 1, 24));
  // A DAC's output range [V]: within ±1000 V, so that its span and the counts per volt are finite.
  dev.motor.dac_v_min = core::require_in_range(motor["dac_v_min"], motor["dac_v_min"].as_double(), -1e3, 1e3, "V");
  dev.motor.dac_v_max = core::require_in_range(motor["dac_v_max"], motor["dac_v_max"].as_double(), -1e3, 1e3, "V");
  if (!(dev.motor.dac_v_max > dev.motor.dac_v_min)) {
    motor["dac_v_max"].fail("expected dac_v_max > dac_v_min");
  }

  const auto tension = root["tension"];
  tension.expect_keys({"min", "max"});
  dev.tension.t_min = tension["min"].as_double();
  dev.tension.t_max = tension["max"].as_double();
  if (dev.tension.t_min < 0.0) tension["min"].fail("expected a tension >= 0 N");
  if (!(dev.tension.t_max > dev.tension.t_min)) tension["max"].fail("expected max > min");
  if (dev.effective_limits().t_max <= dev.effective_limits().t_min) {
    tension.fail("the motor drive cannot produce any tension in [min, max]");
  }

  const auto fingers = root["fingers"];
  if (fingers.size() == 0) fingers.fail("expected at least one finger");
  if (fingers.size() > static_cast<std::size_t>(kMaxConfigFingers)) {
    fingers.fail("expected at most " + std::to_string(kMaxConfigFingers) + " fingers, got " +
                 std::to_string(fingers.size()));
  }
  std::vector<Vec3> p_WA_all;
  for (std::size_t i = 0; i < fingers.size(); ++i) {
    dev.fingers.push_back(parse_finger(fingers.at(i), dev, mpc));
    const FingerConfig& f = dev.fingers.back();
    for (std::size_t j = 0; j < i; ++j) {
      if (dev.fingers[j].name == f.name) {
        fingers.at(i)["name"].fail("duplicate finger name '" + f.name + "'");
      }
      if (f.unit >= 0 && dev.fingers[j].unit == f.unit) {
        fingers.at(i)["unit"].fail("unit " + std::to_string(f.unit) + " is also finger " +
                                   std::to_string(j) + "'s ('" + dev.fingers[j].name +
                                   "'); expected one unit per finger");
      }
    }
    for (int k = 0; k < f.geometry.n; ++k) p_WA_all.push_back(f.geometry.p_WA[k]);
    if (dev.string_count() > kMaxConfigStrings) {
      fingers.at(i)["fulcrums"].fail("this finger brings the device to " +
                                     std::to_string(dev.string_count()) +
                                     " strings; expected at most " +
                                     std::to_string(kMaxConfigStrings) +
                                     " in all (the wire protocol's limit)");
    }
  }
  if (!inside_convex_hull(p_WA_all, dev.p_W_centre)) {
    const auto& c = dev.p_W_centre;
    std::ostringstream os;
    os << "the frame centre (" << c.x() << ", " << c.y() << ", " << c.z()
       << ") m is not inside the fulcrums' convex hull; expected the point the fingertips are "
          "zeroed at, inside the frame";
    if (auto node = root.find("frame_centre")) node->fail(os.str());
    root.fail(os.str());
  }
  return dev;
}

DeviceConfig load_device_config(const std::string& path) {
  return parse_device_config(core::ConfigNode::LoadFile(path));
}

StringVec string_lengths(const PointGeometry& g, const Vec3& p_WF) {
  StringVec l(g.n);
  for (int i = 0; i < g.n; ++i) l[i] = (g.p_WA[i] - p_WF).norm();
  return l;
}

}  // namespace spidar::strings
