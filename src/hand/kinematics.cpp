#include "spidar/hand/kinematics.hpp"

#include <cmath>

#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {
namespace {

// One digit in the right hand's frame H: its four joint points (CMC/MCP … tip), the cap centre
// (index 4), and their derivatives with respect to the digit's parameters, one column each:
// flexion, abduction, distal.
struct DigitLocal {
  std::array<Vec3, 5> p;
  std::array<Mat3, 5> dp;
};

// Bone direction and dorsal normal of a planar flexion chain with frame (u along the bone at
// zero flexion, z dorsal) at accumulated flexion φ: rotating about −v = −(u × z) by φ.
struct Bone {
  Vec3 dir;     // cos φ·u − sin φ·z
  Vec3 dorsal;  // sin φ·u + cos φ·z
};
Bone bone(const Vec3& u, const Vec3& z, double phi) {
  const double c = std::cos(phi);
  const double s = std::sin(phi);
  return {c * u - s * z, s * u + c * z};
}

Vec3 cap_centre(const Vec3& p_tip, const Bone& distal, const Vec3& v, const Vec3& offset) {
  return p_tip + offset.y() * distal.dir + offset.z() * distal.dorsal + offset.x() * v;
}

// Index, middle, ring or little finger. The MCP is fixed in H.
DigitLocal finger_local(const DigitShape& d, double flex, double abd, double distal,
                        Coupling coupling, const Vec3& offset, bool derivs) {
  const Vec3 z = Vec3::UnitZ();
  const Vec3 u0 = d.R_H_digit.col(1);
  const double beta = d.abduction_sign * abd;  // rotation about +z_H
  const Vec3 u = std::cos(beta) * u0 + std::sin(beta) * z.cross(u0);
  const Vec3 v = u.cross(z);
  const CoupledAngle g = couple(coupling, distal);
  const double phi1 = flex;
  const double phi2 = phi1 + g.penultimate;
  const double phi3 = phi2 + distal;
  const Bone b1 = bone(u, z, phi1);
  const Bone b2 = bone(u, z, phi2);
  const Bone b3 = bone(u, z, phi3);

  DigitLocal out;
  const Vec3& m = d.p_H_mcp;
  out.p[0] = m;
  out.p[1] = m + d.length[1] * b1.dir;
  out.p[2] = out.p[1] + d.length[2] * b2.dir;
  out.p[3] = out.p[2] + d.length[3] * b3.dir;
  out.p[4] = cap_centre(out.p[3], b3, v, offset);
  if (!derivs) return out;

  const Vec3 a_abd = d.abduction_sign * z;  // through the MCP
  const Vec3 a_flex = -v;                   // MCP, PIP and DIP share it
  for (int k = 0; k < 5; ++k) {
    const Vec3& p = out.p[k];
    Mat3& D = out.dp[k];
    D.col(0) = a_flex.cross(p - m);
    D.col(1) = a_abd.cross(p - m);
    D.col(2).setZero();
    if (k >= 2) D.col(2) += g.d_penultimate * a_flex.cross(p - out.p[1]);
    if (k >= 3) D.col(2) += a_flex.cross(p - out.p[2]);
  }
  return out;
}

// The thumb: CMC flexion (axis fixed in H), CMC abduction (axis turned by flexion), then the
// coupled MCP/IP chain in the metacarpal's frame.
DigitLocal thumb_local(const HandShape& s, double flex, double abd, double distal,
                       Coupling coupling, const Vec3& offset, bool derivs) {
  const DigitShape& d = s.digits[kThumb];
  const Vec3& c = d.p_H_base;
  const Mat3 R1 = Eigen::AngleAxisd(flex, s.thumb_flexion_axis).toRotationMatrix();
  const Vec3 a_abd = R1 * s.thumb_abduction_axis;
  const Mat3 R_HM = Eigen::AngleAxisd(abd, a_abd).toRotationMatrix() * R1 * d.R_H_digit;
  const Vec3 v = R_HM.col(0);
  const Vec3 u = R_HM.col(1);
  const Vec3 z = R_HM.col(2);
  const CoupledAngle g = couple(coupling, distal);
  const Bone b1 = bone(u, z, g.penultimate);
  const Bone b2 = bone(u, z, g.penultimate + distal);

  DigitLocal out;
  out.p[0] = c;
  out.p[1] = c + d.length[0] * u;
  out.p[2] = out.p[1] + d.length[1] * b1.dir;
  out.p[3] = out.p[2] + d.length[2] * b2.dir;
  out.p[4] = cap_centre(out.p[3], b2, v, offset);
  if (!derivs) return out;

  const Vec3& a_cmc = s.thumb_flexion_axis;  // through the CMC
  const Vec3 a_flex = -v;                    // MCP and IP
  for (int k = 0; k < 5; ++k) {
    const Vec3& p = out.p[k];
    Mat3& D = out.dp[k];
    D.col(0) = a_cmc.cross(p - c);
    D.col(1) = a_abd.cross(p - c);
    D.col(2).setZero();
    if (k >= 2) D.col(2) += g.d_penultimate * a_flex.cross(p - out.p[1]);
    if (k >= 3) D.col(2) += a_flex.cross(p - out.p[2]);
  }
  return out;
}

// Writes the 3×20 block of one point: wrist translation, wrist rotation, the digit's columns.
template <typename Derived>
void write_jacobian(Eigen::MatrixBase<Derived>& J, int row, const Mat3& J_rot, const Mat3& A,
                    const Mat3& dp_H, const DigitParams& cols) {
  J.template block<3, 3>(row, kWristX).setIdentity();
  J.template block<3, 3>(row, kWristRotX) = J_rot;
  const Mat3 dp_W = A * dp_H;
  J.template block<3, 1>(row, cols.flexion) = dp_W.col(0);
  if (cols.abduction >= 0) J.template block<3, 1>(row, cols.abduction) = dp_W.col(1);
  J.template block<3, 1>(row, cols.distal) = dp_W.col(2);
}

}  // namespace

Pose hand_pose(const HandParams& params) {
  return Pose{Quat(rotation_from_vector(params.r_W_hand())), params.p_W_wrist()};
}

HandPoints forward_kinematics(const HandModel& model, const HandParams& params) {
  HandPoints points;
  forward_kinematics(model, params, &points, nullptr, nullptr);
  return points;
}

void forward_kinematics(const HandModel& model, const HandParams& params, HandPoints* points,
                        FingertipJacobian* J_fingertips, JointJacobian* J_joints) {
  const bool derivs = J_fingertips != nullptr || J_joints != nullptr;
  const auto& q = params.q;
  const Vec3 p_W_wrist = params.p_W_wrist();
  const Vec3 r = params.r_W_hand();
  // A = R_WH·M maps right-hand coordinates in H to world directions.
  Mat3 A = rotation_from_vector(r);
  if (model.side == Side::kLeft) A.col(0) = -A.col(0);
  const Mat3 J_l = derivs ? so3_left_jacobian(r) : Mat3::Identity();
  const Vec3& offset = model.shape.dimensions.fingertip_offset;

  if (J_fingertips) J_fingertips->setZero();
  if (J_joints) {
    J_joints->setZero();
    J_joints->block<3, 3>(3 * kWristJoint, kWristX).setIdentity();
  }
  if (points) points->p_W_joint[kWristJoint] = p_W_wrist;

  for (int f = 0; f < kFingerCount; ++f) {
    const DigitParams cols = digit_params(f, params.little_independent);
    const double flex = q[cols.flexion];
    const double abd = cols.abduction >= 0 ? q[cols.abduction] : 0.0;
    const double distal = q[cols.distal];
    const DigitLocal local =
        f == kThumb ? thumb_local(model.shape, flex, abd, distal, model.coupling, offset, derivs)
                    : finger_local(model.shape.digits[f], flex, abd, distal, model.coupling, offset,
                                   derivs);
    const int last = f < kFingertipCount ? 5 : 4;  // the little finger has no cap
    for (int k = 0; k < last; ++k) {
      const Vec3 d_W = A * local.p[k];  // p_W − p_W_wrist
      const bool is_cap = k == 4;
      if (points) {
        if (is_cap) {
          points->p_W_fingertip[f] = p_W_wrist + d_W;
        } else {
          points->p_W_joint[joint_index(f, k)] = p_W_wrist + d_W;
        }
      }
      if (!derivs) continue;
      const Mat3 J_rot = -skew(d_W) * J_l;
      if (is_cap && J_fingertips) {
        write_jacobian(*J_fingertips, 3 * f, J_rot, A, local.dp[k], cols);
      } else if (!is_cap && J_joints) {
        write_jacobian(*J_joints, 3 * joint_index(f, k), J_rot, A, local.dp[k], cols);
      }
    }
  }
}

}  // namespace spidar::hand
