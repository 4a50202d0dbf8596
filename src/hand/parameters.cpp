#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

std::string_view param_name(int param) {
  static constexpr std::array<std::string_view, kParamCount> kNames = {"wrist_x",
                                                                       "wrist_y",
                                                                       "wrist_z",
                                                                       "wrist_rot_x",
                                                                       "wrist_rot_y",
                                                                       "wrist_rot_z",
                                                                       "thumb_cmc_flexion",
                                                                       "thumb_cmc_abduction",
                                                                       "thumb_ip",
                                                                       "index_mcp_flexion",
                                                                       "index_mcp_abduction",
                                                                       "index_dip",
                                                                       "middle_mcp_flexion",
                                                                       "middle_dip",
                                                                       "ring_mcp_flexion",
                                                                       "ring_mcp_abduction",
                                                                       "ring_dip",
                                                                       "little_mcp_flexion",
                                                                       "little_mcp_abduction",
                                                                       "little_dip"};
  return (param >= 0 && param < kParamCount) ? kNames[param] : std::string_view("invalid");
}

DigitParams digit_params(int finger, bool little_independent) {
  if (finger == kLittle && little_independent) return {kLittleMcpFlexion, kLittleMcpAbduction, kLittleDip};
  switch (finger) {
    case kThumb:
      return {kThumbCmcFlexion, kThumbCmcAbduction, kThumbIp};
    case kIndex:
      return {kIndexMcpFlexion, kIndexMcpAbduction, kIndexDip};
    case kMiddle:
      return {kMiddleMcpFlexion, -1, kMiddleDip};
    case kRing:
    case kLittle:
    default:
      return {kRingMcpFlexion, kRingMcpAbduction, kRingDip};
  }
}

std::string_view joint_name(int joint) {
  static constexpr std::array<std::string_view, kJointCount> kNames = {
      "wrist",      "thumb_cmc",  "thumb_mcp", "thumb_ip",   "thumb_tip",  "index_mcp",
      "index_pip",  "index_dip",  "index_tip", "middle_mcp", "middle_pip", "middle_dip",
      "middle_tip", "ring_mcp",   "ring_pip",  "ring_dip",   "ring_tip",   "little_mcp",
      "little_pip", "little_dip", "little_tip"};
  return (joint >= 0 && joint < kJointCount) ? kNames[joint] : std::string_view("invalid");
}

HandParams mirror_params(const HandParams& params) {
  HandParams out = params;
  out.q[kWristX] = -params.q[kWristX];
  out.q[kWristRotY] = -params.q[kWristRotY];
  out.q[kWristRotZ] = -params.q[kWristRotZ];
  return out;
}

}  // namespace spidar::hand
