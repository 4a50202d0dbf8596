#pragma once
/// The bones a simulated user's skin is bound to (sim/anatomical_hand.hpp), and their frames at a
/// pose of the 17-parameter skeleton (hand/kinematics.hpp).
///
/// Bones: the forearm, the palm (carpus and the four finger metacarpals, rigid in the hand frame
/// H), the thumb's metacarpal, proximal and distal phalanges, and the proximal, middle and distal
/// phalanges of the index, middle, ring and little fingers: 17 in all. The hand model has no wrist
/// joint, so the forearm moves with the hand frame (it is its own bone so that a wrist could be
/// added later without touching the skin's weights).
///
/// Bone frame B: origin at the bone's proximal joint (palm and forearm: the wrist, H's origin),
/// y along the bone (proximal to distal joint), z dorsal (nail side), x = y × z; for a phalanx or
/// the thumb's metacarpal x is the digit's flexion axis negated (kinematics.hpp: flexion turns
/// about −x). Frames are given in H with the right hand's numbers (hand_shape.hpp), for either
/// side: the left hand's world pose mirrors them in x_H.
#include <array>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::sim {

enum HandBone : int {
  kForearmBone = 0,
  kPalmBone = 1,
  kThumbMetacarpalBone = 2,
  // then the phalanges: phalanx_bone()
};
inline constexpr int kHandBoneCount = 17;

/// The bone of phalanx k (0 = proximal) of a digit: thumb k = 0, 1; fingers k = 0, 1, 2.
constexpr int phalanx_bone(int finger, int k) {
  return finger == hand::kThumb ? 3 + k : 5 + 3 * (finger - 1) + k;
}

/// Frames of all bones in H (right-hand numbers): R_HB columns are B's axes, p_HB its origin [m].
struct HandBoneFrames {
  std::array<Mat3, kHandBoneCount> R_HB;
  std::array<Vec3, kHandBoneCount> p_HB;
};

/// The bone frames of `model` posed by `params` (wrist pose ignored: frames are in H). Joint
/// positions come from hand::forward_kinematics, so the bones end exactly on the model's joints;
/// the little finger follows its own parameters (17..19) when little_independent. Allocates nothing.
HandBoneFrames hand_bone_frames(const hand::HandModel& model, const hand::HandParams& params);

}  // namespace spidar::sim
