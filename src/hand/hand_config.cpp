#include "spidar/hand/hand_config.hpp"

#include <string>

#include "spidar/core/units.hpp"

namespace spidar::hand {
namespace {

Interval parse_range_deg(const core::ConfigNode& node) {
  const auto v = node.as_doubles();
  if (v.size() != 2)
    node.fail("expected [lo, hi] in degrees, got " + std::to_string(v.size()) + " numbers");
  if (!(v[0] < v[1])) node.fail("expected lo < hi");
  if (v[0] < -180.0 || v[1] > 180.0) node.fail("expected degrees within [-180, 180]");
  return {units::deg_to_rad(v[0]), units::deg_to_rad(v[1])};
}

JointRanges parse_ranges(const core::ConfigNode& node) {
  node.expect_keys({"mcp_flexion", "mcp_abduction", "pip_flexion", "dip_flexion",
                    "thumb_cmc_flexion", "thumb_cmc_abduction", "thumb_mcp_flexion",
                    "thumb_ip_flexion"});
  JointRanges r;
  const std::pair<const char*, Interval*> fields[] = {
      {"mcp_flexion", &r.mcp_flexion},
      {"mcp_abduction", &r.mcp_abduction},
      {"pip_flexion", &r.pip_flexion},
      {"dip_flexion", &r.dip_flexion},
      {"thumb_cmc_flexion", &r.thumb_cmc_flexion},
      {"thumb_cmc_abduction", &r.thumb_cmc_abduction},
      {"thumb_mcp_flexion", &r.thumb_mcp_flexion},
      {"thumb_ip_flexion", &r.thumb_ip_flexion},
  };
  for (const auto& [key, range] : fields) {
    if (auto child = node.find(key)) *range = parse_range_deg(*child);
  }
  if (auto s = validate_joint_ranges(r); !s.ok()) node.fail(s.error().message);
  return r;
}

HandProfile parse_profile(const core::ConfigNode& node) {
  node.expect_keys({"name", "length", "width", "thickness", "fingertip_offset", "coupling",
                    "joint_ranges_deg"});
  HandProfile p;
  p.name = node["name"].as_string();
  if (p.name.empty()) node["name"].fail("expected a non-empty name");

  const auto length = node["length"];
  p.dimensions.length = core::require_in_range(length, length.as_double(), 0.12, 0.26, "m");
  const auto width = node["width"];
  p.dimensions.width = core::require_in_range(width, width.as_double(), 0.05, 0.13, "m");
  const double ratio = p.dimensions.width / p.dimensions.length;
  if (ratio < 0.3 || ratio > 0.65) {
    width.fail("expected width/length in [0.3, 0.65], got " + std::to_string(ratio));
  }
  if (auto thickness = node.find("thickness"))
    p.dimensions.thickness = core::require_in_range(*thickness, thickness->as_double(), 0.6, 1.6, "");
  if (auto offset = node.find("fingertip_offset")) {
    p.dimensions.fingertip_offset = offset->as_vec3();
    if (p.dimensions.fingertip_offset.norm() > 0.02) {
      offset->fail("expected an offset of at most 0.02 m (metres, not millimetres?)");
    }
  }
  if (auto coupling = node.find("coupling")) {
    const auto c = coupling_from_name(coupling->as_string());
    if (!c) coupling->fail("expected 'quadratic' or 'linear', got '" + coupling->as_string() + "'");
    p.coupling = *c;
  }
  if (auto ranges = node.find("joint_ranges_deg")) p.ranges = parse_ranges(*ranges);
  // Everything above mirrors validate_dimensions; keep the two in step.
  if (auto s = validate_dimensions(p.dimensions); !s.ok()) node.fail(s.error().message);
  return p;
}

}  // namespace

HandModel HandProfile::model(Side side) const {
  return make_hand_model(side, dimensions, coupling, ranges).value();
}

const HandProfile* HandProfiles::find(std::string_view name) const {
  for (const auto& p : profiles) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

HandProfiles parse_hand_profiles(const core::ConfigNode& root) {
  root.expect_keys({"hands"});
  HandProfiles out;
  out.source = root.file();
  const auto hands = root["hands"];
  if (hands.size() == 0) hands.fail("expected at least one hand profile");
  for (std::size_t i = 0; i < hands.size(); ++i) {
    out.profiles.push_back(parse_profile(hands.at(i)));
    for (std::size_t j = 0; j < i; ++j) {
      if (out.profiles[j].name == out.profiles[i].name) {
        hands.at(i)["name"].fail("duplicate hand profile name '" + out.profiles[i].name + "'");
      }
    }
  }
  return out;
}

HandProfiles load_hand_profiles(const std::string& path) {
  return parse_hand_profiles(core::ConfigNode::LoadFile(path));
}

}  // namespace spidar::hand
