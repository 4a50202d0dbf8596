#pragma once
/// Joint-ball targets (paper, eq. 21): for a projected joint P with ball radius r and four
/// neighbours P_i on the ball (two across the bone, two along it),
///   P̃ = P + α Σ τ_i (P_i − P),   τ_i = 1 if P_i lies on the real hand's silhouette, else 0.
/// A joint whose ball lies wholly inside the silhouette stays; one near the silhouette's edge is
/// pushed back inside. The radius is the bone's projected radius (its capsule radius over depth,
/// times the focal length) times a configurable scale.
#include <array>
#include <opencv2/core/mat.hpp>

#include "spidar/core/types.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

struct JointBall {
  bool used = false;             ///< false for joints without a ball (wrist, tips, off-image)
  Vec2 centre_px = Vec2::Zero(); ///< P [px]
  double radius_px = 0;          ///< r [px]
  int on_count = 0;              ///< neighbours on the silhouette (0..4)
  Vec2 target_px = Vec2::Zero(); ///< P̃ [px]
};

using JointBalls = std::array<JointBall, hand::kJointCount>;

/// P̃ of one projected joint, given its bone direction in the image (unit, or zero for "axis
/// aligned neighbours") and the matte (CV_32FC1, 1 = hand). `on_count` may be null.
Vec2 joint_ball_target(const cv::Mat& alpha, const Vec2& centre_px, const Vec2& bone_dir_px,
                       double radius_px, double gain, double threshold, int* on_count);

/// The balls of one posed hand's joints: MCP, PIP and DIP of every finger (little included) and
/// the thumb's CMC, MCP and IP, each with its neighbours along the projected bone leaving the
/// joint. No ball at the wrist or the tips, nor for joints off the image or within 1 cm of the
/// camera plane. No balls at all if `alpha` is empty.
void joint_ball_targets(const hand::HandModel& model, const hand::HandPoints& points,
                        const vision::Camera& camera, const cv::Mat& alpha,
                        const RegistrationParams& params, JointBalls* balls);

}  // namespace spidar::registration
