#pragma once
/// Where a forearm points. The 17-DOF hand has no wrist joint: its forearm, if drawn in line with
/// the hand (along −y_H), swings with every turn of the hand as if the elbow went round with it,
/// and a hand turned back toward the camera pointed its forearm into it. A real forearm points
/// from the wrist to the elbow, which stays put while the hand turns; the wrist bends, but only
/// so far (flexion and deviation of 60–80° and 20–30°). Here the forearm points at an elbow point
/// and bends away from the hand's axis by at most a given angle, the same in every direction (a
/// cone: a simplification of the wrist's flexion and deviation ranges); beyond it, the elbow gives
/// way.
#include "spidar/core/pose.hpp"
#include "spidar/core/types.hpp"
#include "spidar/hand/parameters.hpp"

namespace spidar::hand {

/// Unit direction [world] from the wrist p_W_wrist toward the elbow p_W_elbow, turned back toward
/// the hand's own axis −y_H (R_WH: the hand's rotation) until it is at most max_bend_rad from it
/// ([0, π]; outside, or not finite: −y_H, no bend). An elbow at the wrist or not finite gives −y_H.
Vec3 forearm_direction(const Mat3& R_WH, const Vec3& p_W_wrist, const Vec3& p_W_elbow, double max_bend_rad);

/// The wrist's bend: the shortest rotation [world] taking the hand's axis −y_H onto
/// toward_elbow_W (unit). Applied to the forearm drawn in line with the hand, it points the
/// forearm along toward_elbow_W, pronated with the hand.
Mat3 wrist_bend(const Mat3& R_WH, const Vec3& toward_elbow_W);

/// The forearm's frame F: the hand's pose X_WH bent at the wrist (wrist_bend) so that its −y axis
/// points along toward_elbow_W (unit, world); at the wrist, p_WF = p_WH.
Pose forearm_pose(const Pose& X_WH, const Vec3& toward_elbow_W);

/// The elbow of a forearm in line with the hand at pose q, forearm_length_m from the wrist [world].
Vec3 elbow_in_line(const HandParams& q, double forearm_length_m);

}  // namespace spidar::hand
