#pragma once
/// Forward kinematics of the hand (the paper's 17 parameters and the little finger's own 3) and its analytic Jacobians.
///
/// p_W = p_W_wrist + R_WH · M · p_H(fingers), with R_WH = exp([r_W_hand]×) and M = diag(−1, 1, 1)
/// for the left hand, I for the right (hand_shape.hpp). Each digit is a chain of revolute joints:
///   fingers: MCP abduction (about ±z_H), MCP flexion, PIP, DIP (all three about the same axis,
///            −x of the abducted finger frame, so flexion curls toward the palm);
///   thumb:   CMC flexion (about −z_H), CMC abduction (about z_H × y_thumb, turned by flexion),
///            MCP and IP flexion (about −x of the thumb's metacarpal frame).
/// The PIP (thumb: MCP) angle is coupling(distal parameter) (coupling.hpp); the little finger uses
/// the ring finger's parameters, or its own (17..19) with HandParams::little_independent. Parameters are used as given: clamp them first if they may be
/// out of range (joint_limits.hpp).
///
/// Jacobian columns: a revolute joint with world axis a through t moves p by a × (p − t); the
/// coupled parameter adds dθ2/dθ1 · a × (p − t_penultimate) + a × (p − t_distal); the wrist
/// translation gives the identity; the rotation vector gives −[p − p_W_wrist]× · J_l(r), exact
/// (rotation_vector.hpp). Nothing here allocates.
#include <array>

#include "spidar/core/pose.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

/// World positions [m] of the joints (order: parameters.hpp, joint_index) and of the four
/// measured fingertips: the centres of the caps where the strings attach (thumb, index, middle,
/// ring).
struct HandPoints {
  std::array<Vec3, kJointCount> p_W_joint;
  std::array<Vec3, kFingertipCount> p_W_fingertip;
};

/// ∂p_W/∂q of the fingertips stacked: rows 3i..3i+2 belong to fingertip i [m/m or m/rad].
using FingertipJacobian = Eigen::Matrix<double, 3 * kFingertipCount, kParamCount>;
/// ∂p_W/∂q of the joints stacked: rows 3j..3j+2 belong to joint j.
using JointJacobian = Eigen::Matrix<double, 3 * kJointCount, kParamCount>;

/// X_WH: the hand frame in world (R_WH = exp([r]×), origin at the wrist). For the left hand the
/// hand-frame coordinates of the body are mirrored in x before X_WH applies (see above).
Pose hand_pose(const HandParams& params);

/// World positions of all joints and measured fingertips.
HandPoints forward_kinematics(const HandModel& model, const HandParams& params);

/// Forward kinematics and, for each non-null output, its Jacobian. `points` may also be null.
void forward_kinematics(const HandModel& model, const HandParams& params, HandPoints* points,
                        FingertipJacobian* J_fingertips, JointJacobian* J_joints);

}  // namespace spidar::hand
