#pragma once
/// Registration metrics against ground truth: silhouette IoU, projected joint error [px],
/// fingertip error [mm].
#include <array>
#include <opencv2/core/mat.hpp>

#include "spidar/hand/kinematics.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

/// |A ∩ B| / |A ∪ B| of two CV_8UC1 masks (non-zero = inside); 1 when both are empty. Throws
/// SpidarError if the masks are not CV_8UC1 or differ in size.
double mask_iou(const cv::Mat& a, const cv::Mat& b);

/// Mean image distance [px] between the projected joints of a fitted and a true hand (all 21
/// joints; joints behind the camera are skipped).
double joint_px_error(const hand::HandPoints& fitted, const hand::HandPoints& truth,
                      const vision::Camera& camera);

/// Mean 3D distance [m] between the four fingertip caps of a fitted and a true hand.
double fingertip_error_m(const hand::HandPoints& fitted, const hand::HandPoints& truth);

/// How the fitted palm is turned against the true one: the rotation vector [rad] of R_tᵀ R_f
/// (R = hand_pose(q).R), in the true hand's own axes as the right hand's numbers give them
/// (hand_shape.hpp): x across the palm toward the little finger (about it: the palm pitched), y
/// along the hand toward the fingers (rolled), z out of the back of the hand (turned in its
/// plane). The left hand's mirrored body (hand_pose) is mirrored back, so a fit and its mirror
/// image give the same vector.
Vec3 palm_rotation_error_rad(const hand::HandParams& fitted, const hand::HandParams& truth,
                             hand::Side side);

}  // namespace spidar::registration
