#include "spidar/sim/hand_bones.hpp"

#include <cmath>

#include "spidar/hand/kinematics.hpp"

namespace spidar::sim {
namespace {

// The frame of a bone from its proximal joint a to its distal joint b, with x the digit's lateral
// axis v (perpendicular to the bone: all of a digit's flexion axes are −v).
void phalanx_frame(const Vec3& a, const Vec3& b, const Vec3& v, Mat3* R, Vec3* p) {
  const Vec3 y = (b - a).normalized();
  R->col(0) = v;
  R->col(1) = y;
  R->col(2) = v.cross(y);
  *p = a;
}

}  // namespace

HandBoneFrames hand_bone_frames(const hand::HandModel& model, const hand::HandParams& params) {
  // Joint positions in H: forward kinematics with the wrist at the origin, unrotated, then the
  // left hand's mirror undone (x_H of the right hand's numbers).
  hand::HandParams local = params;
  local.set_wrist(Vec3::Zero(), Vec3::Zero());
  hand::HandPoints points;
  hand::forward_kinematics(model, local, &points, nullptr, nullptr);
  if (model.side == hand::Side::kLeft)
    for (Vec3& p : points.p_W_joint) p.x() = -p.x();
  auto joint = [&](int f, int k) -> const Vec3& { return points.p_W_joint[hand::joint_index(f, k)]; };

  HandBoneFrames out;
  for (int b : {kForearmBone, kPalmBone}) {
    out.R_HB[b] = Mat3::Identity();
    out.p_HB[b] = Vec3::Zero();
  }

  // Thumb: the metacarpal's frame after CMC flexion (about an axis fixed in H) and abduction
  // (about an axis turned by flexion), as in hand::forward_kinematics.
  const hand::HandShape& s = model.shape;
  const hand::DigitParams tp = hand::digit_params(hand::kThumb);
  const Mat3 R1 = Eigen::AngleAxisd(params[tp.flexion], s.thumb_flexion_axis).toRotationMatrix();
  const Vec3 a_abd = R1 * s.thumb_abduction_axis;
  const Mat3 R_HM = Eigen::AngleAxisd(params[tp.abduction], a_abd).toRotationMatrix() * R1 *
                    s.digits[hand::kThumb].R_H_digit;
  out.R_HB[kThumbMetacarpalBone] = R_HM;
  out.p_HB[kThumbMetacarpalBone] = joint(hand::kThumb, 0);
  for (int k = 0; k < 2; ++k) {
    const int b = phalanx_bone(hand::kThumb, k);
    phalanx_frame(joint(hand::kThumb, k + 1), joint(hand::kThumb, k + 2), R_HM.col(0), &out.R_HB[b],
                  &out.p_HB[b]);
  }

  // Fingers: abduction turns the digit about ±z_H; flexion then bends it about −v, v = u × z_H.
  for (int f = hand::kIndex; f <= hand::kLittle; ++f) {
    const hand::DigitShape& d = s.digits[f];
    const hand::DigitParams cols = hand::digit_params(f, params.little_independent);
    const double abd = cols.abduction >= 0 ? params[cols.abduction] : 0.0;
    const double beta = d.abduction_sign * abd;
    const Vec3 z = Vec3::UnitZ();
    const Vec3 u0 = d.R_H_digit.col(1);
    const Vec3 u = std::cos(beta) * u0 + std::sin(beta) * z.cross(u0);
    const Vec3 v = u.cross(z).normalized();
    for (int k = 0; k < 3; ++k) {
      const int b = phalanx_bone(f, k);
      phalanx_frame(joint(f, k), joint(f, k + 1), v, &out.R_HB[b], &out.p_HB[b]);
    }
  }
  return out;
}

}  // namespace spidar::sim
