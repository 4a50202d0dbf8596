#pragma once
/// Users' hand sizes from configs/hands.yaml, validated on load:
///
///   hands:
///     - name: model                      # unique
///       length: 0.19                     # m, wrist crease to middle fingertip
///       width: 0.085                     # m, palm breadth across the MCP joints
///       fingertip_offset: [0, -0.008, 0] # m, optional (hand_shape.hpp)
///       coupling: quadratic              # optional: quadratic (paper, default) | linear
///       joint_ranges_deg:                # optional overrides, [lo, hi] in degrees
///         mcp_flexion: [-15, 90]
///
/// Errors name file:line: key, e.g. `hands.yaml:7: hands[1].width: expected ...`.
#include <string>
#include <string_view>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/hand/hand_model.hpp"

namespace spidar::hand {

struct HandProfile {
  std::string name;
  HandDimensions dimensions;
  Coupling coupling = Coupling::kPaperQuadratic;
  JointRanges ranges;

  /// The model of one hand of this user (both hands share the sizes).
  HandModel model(Side side) const;
};

struct HandProfiles {
  std::string source;  ///< file it was loaded from
  std::vector<HandProfile> profiles;

  /// The profile called `name`, or nullptr.
  const HandProfile* find(std::string_view name) const;
};

/// Parses and validates. Throws core::ConfigError naming file:line: key.
HandProfiles parse_hand_profiles(const core::ConfigNode& root);
/// Loads and validates a hands file.
HandProfiles load_hand_profiles(const std::string& path);

}  // namespace spidar::hand
