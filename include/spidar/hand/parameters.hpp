#pragma once
/// The paper's reduced hand model: 17 parameters per hand (26 anatomical DOF reduced by
/// coupling the last two joints of each digit and by letting the little finger copy the ring),
/// followed by the little finger's own three, used only where it moves on its own
/// (HandParams::little_independent; registration's `little_finger: free`).
///
///   index  parameter                              unit
///   0..2   p_W_wrist: wrist centre in world       m
///   3..5   r_W_hand: rotation vector of the hand  rad   (R_WH = exp([r]×), world frame)
///   6      thumb CMC flexion                      rad
///   7      thumb CMC abduction                    rad
///   8      thumb IP flexion (MCP = coupling(IP))  rad
///   9      index MCP flexion                      rad
///   10     index MCP abduction                    rad
///   11     index DIP flexion (PIP = coupling(DIP)) rad
///   12     middle MCP flexion                     rad
///   13     middle DIP flexion (PIP = coupling)    rad
///   14     ring MCP flexion                       rad   (little finger copies 14..16)
///   15     ring MCP abduction                     rad
///   16     ring DIP flexion (PIP = coupling)      rad
///   17     little MCP flexion                     rad   (only with little_independent)
///   18     little MCP abduction                   rad   (ditto)
///   19     little DIP flexion (PIP = coupling)    rad   (ditto)
///
/// The coupled parameter of each digit is its distal angle (see coupling.hpp). Positive flexion
/// curls a digit toward the palm; positive finger abduction spreads a finger away from the
/// middle finger. The same parameter values give mirror-image poses on the left and right hand
/// (relative to the hand frame; the wrist pose is always in world).
#include <array>
#include <string_view>

#include "spidar/core/types.hpp"

namespace spidar::hand {

inline constexpr int kParamCount = 20;
/// The paper's parameters: 0..16 (what a recording stores and what the paper's fit moves).
inline constexpr int kPaperParamCount = 17;
using ParamVec = Eigen::Matrix<double, kParamCount, 1>;

/// Index 0 = left, 1 = right (everywhere in spidar).
enum class Side : int { kLeft = 0, kRight = 1 };

enum Param : int {
  kWristX = 0,
  kWristY = 1,
  kWristZ = 2,
  kWristRotX = 3,
  kWristRotY = 4,
  kWristRotZ = 5,
  kThumbCmcFlexion = 6,
  kThumbCmcAbduction = 7,
  kThumbIp = 8,
  kIndexMcpFlexion = 9,
  kIndexMcpAbduction = 10,
  kIndexDip = 11,
  kMiddleMcpFlexion = 12,
  kMiddleDip = 13,
  kRingMcpFlexion = 14,
  kRingMcpAbduction = 15,
  kRingDip = 16,
  kLittleMcpFlexion = 17,
  kLittleMcpAbduction = 18,
  kLittleDip = 19,
};

/// Short name of a parameter for messages and plots, e.g. "index_mcp_abduction".
std::string_view param_name(int param);

/// Digits in the paper's order, then the little finger (modelled, not measured).
enum Finger : int { kThumb = 0, kIndex = 1, kMiddle = 2, kRing = 3, kLittle = 4 };
inline constexpr int kFingerCount = 5;
/// Measured fingertips (the strings' caps): thumb, index, middle, ring.
inline constexpr int kFingertipCount = 4;

/// Parameters of one digit: flexion, abduction (-1 if the digit has none) and the coupled
/// distal parameter. The little finger returns the ring finger's parameters (the paper's model),
/// or its own (17..19) when `little_independent`.
struct DigitParams {
  int flexion;
  int abduction;
  int distal;
};
DigitParams digit_params(int finger, bool little_independent = false);

/// Joint positions in a fixed order: the wrist, then for each digit four points from proximal
/// to distal. Fingers: MCP, PIP, DIP, tip (end of the distal bone). Thumb: CMC, MCP, IP, tip.
inline constexpr int kJointCount = 1 + 4 * kFingerCount;  // 21
inline constexpr int kWristJoint = 0;
/// Index of point k (0 = MCP/CMC ... 3 = tip) of a digit.
constexpr int joint_index(int finger, int k) {
  return 1 + 4 * finger + k;
}
/// Short name of a joint, e.g. "index_pip", "thumb_cmc".
std::string_view joint_name(int joint);

/// The parameters of one hand with named access. A plain value type; no invariants.
struct HandParams {
  ParamVec q = ParamVec::Zero();
  /// The paper's little finger copies the ring finger's parameters (14..16), and q[17..19] are
  /// unused. A real hand's does not: with `little_independent` the little finger takes its own
  /// q[17..19] = (MCP flexion, MCP abduction, DIP) [rad] (the simulated users' hands, and the
  /// registration with `little_finger: free`), and the Jacobians have columns for them.
  bool little_independent = false;

  /// The little finger's own parameters, q[17..19] [rad].
  Vec3 little() const { return q.segment<3>(kLittleMcpFlexion); }
  void set_little(const Vec3& v) { q.segment<3>(kLittleMcpFlexion) = v; }
  /// The ring finger's parameters, q[14..16] [rad] (what a coupled little finger copies).
  Vec3 ring() const { return q.segment<3>(kRingMcpFlexion); }

  Vec3 p_W_wrist() const { return q.segment<3>(kWristX); }
  Vec3 r_W_hand() const { return q.segment<3>(kWristRotX); }
  void set_wrist(const Vec3& p_W_wrist, const Vec3& r_W_hand) {
    q.segment<3>(kWristX) = p_W_wrist;
    q.segment<3>(kWristRotX) = r_W_hand;
  }
  double& operator[](int i) { return q[i]; }
  double operator[](int i) const { return q[i]; }
};

/// Parameters that pose the other hand as the mirror image across the world plane x = 0:
/// wrist (x, y, z) → (−x, y, z), rotation vector (rx, ry, rz) → (rx, −ry, −rz), fingers unchanged.
HandParams mirror_params(const HandParams& params);

}  // namespace spidar::hand
