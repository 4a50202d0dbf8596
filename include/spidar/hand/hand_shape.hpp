#pragma once
/// The sizes of one user's hand: anatomical default proportions scaled by the hand's length and
/// width, and the fixed geometry the kinematics needs, all in the hand frame H.
///
/// Hand frame H (of the right hand): origin at the wrist centre, y toward the fingers along the
/// middle finger's metacarpal, z dorsal (back of the hand), x = y × z toward the little finger.
/// With R_WH = I the right hand lies palm down with the fingers pointing away from the user
/// (world y) and the little finger toward the user's right (world x). The left hand uses the
/// same numbers mirrored in x (x_H of the left hand points to its thumb side), so with R_WH = I
/// it too lies palm down, fingers away from the user.
///
/// Proportions (a published set): segment lengths are fractions of a 0.0959 m unit for a 0.19 m hand
/// (unit = 0.5047 × hand length), e.g. index metacarpal/proximal/middle/distal
/// 0.66/0.366/0.232/0.202. Lengths along the digits scale with the hand length; positions across
/// the palm and the capsule radii scale with the hand width. The carpal offset (wrist to the
/// metacarpal bases) is chosen so that wrist → middle fingertip is exactly the hand length with
/// the fingers straight.
#include <array>
#include <string>

#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

/// A user's measurements.
struct HandDimensions {
  double length = 0.19;  ///< wrist crease to the middle fingertip, fingers straight [m]
  double width = 0.085;  ///< palm breadth across the MCP joints, index to little [m]
  /// Centre of the fingertip cap (where the strings attach) relative to the end of the distal
  /// bone, in the distal bone's frame: x lateral (toward the little finger on the right hand),
  /// y along the bone (distal positive), z dorsal (nail side) [m]. Not scaled by the hand size.
  Vec3 fingertip_offset{0.0, -0.008, 0.0};
  /// The digits' capsule radii relative to the published proportions (which scale with width):
  /// a hand's finger thickness, apart from its palm breadth. 1 = the proportions.
  double thickness = 1.0;
};

/// Checks measurements: length in [0.12, 0.26] m, width in [0.05, 0.13] m, width/length in
/// [0.3, 0.65], thickness in [0.6, 1.6], fingertip offset finite and at most 0.02 m long. The
/// error names the field.
Status validate_dimensions(const HandDimensions& dims);

/// One digit of the right hand at the zero pose, in H.
struct DigitShape {
  /// Metacarpal base (thumb: the CMC joint) [m].
  Vec3 p_H_base = Vec3::Zero();
  /// Digit frame at the zero pose: y along the digit, z dorsal (nail side), x = y × z.
  Mat3 R_H_digit = Mat3::Identity();
  /// Segment lengths [m]: metacarpal, then the phalanges (fingers: proximal, middle, distal;
  /// thumb: proximal, distal, and length[3] = 0).
  std::array<double, 4> length{};
  /// Capsule radius per segment [m], same order as `length`.
  std::array<double, 4> radius{};
  /// Number of phalanges: 3 for fingers, 2 for the thumb.
  int phalanges = 3;
  /// Fingers: +1 if positive abduction rotates about +z_H (index), −1 about −z_H (ring,
  /// little), 0 for no abduction (middle). Unused for the thumb.
  double abduction_sign = 0.0;
  /// The MCP joint at the zero pose, p_H_base + length[0]·y_digit [m] (fixed for the fingers;
  /// the thumb's moves with its CMC joint).
  Vec3 p_H_mcp = Vec3::Zero();
};

/// A box, e.g. the palm: centre and half extents along the axes of H [m].
struct PalmBox {
  Vec3 p_H_centre = Vec3::Zero();
  Vec3 half_extents = Vec3::Zero();
};

/// Everything the kinematics and the render geometry need for one user's hand (right-hand
/// numbers; see the file comment for the left hand).
struct HandShape {
  HandDimensions dimensions;
  std::array<DigitShape, kFingerCount> digits{};  ///< thumb, index, middle, ring, little
  /// Thumb CMC axes in H at the zero pose (through the CMC joint). Flexion (first joint, fixed
  /// in H) is about −z_H: positive moves the thumb across the palm toward the little finger.
  /// Abduction (second joint, turned by flexion) is about z_H × y_thumb: positive moves the
  /// thumb away from the palm (palmar abduction).
  Vec3 thumb_flexion_axis = -Vec3::UnitZ();
  Vec3 thumb_abduction_axis = Vec3::UnitX();
  PalmBox palm;
};

/// Builds the shape from measurements. Fails (naming the field) if they are invalid.
Result<HandShape> make_hand_shape(const HandDimensions& dims);

/// The default model hand (0.19 m long, 0.085 m wide).
const HandShape& default_hand_shape();

}  // namespace spidar::hand
