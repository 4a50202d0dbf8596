#pragma once
/// Where the fingertip ends beyond the string's cap, read from the image: evidence on the caps'
/// offset along the distal bone (HandDimensions::fingertip_offset's y), which the strings alone do
/// not determine (a cap worn further back is reached as well by a longer or more bent finger).
///
/// The cap's centre is measured in 3D by the strings; the distal phalanx's axis comes from the
/// fitted pose. From the cap's projection the matte is walked along the projected axis, distally,
/// until it ends (the fingertip's outline). That image distance, taken back onto the 3D axis, is
/// how far the finger reaches beyond its cap: −fingertip_offset.y for a fingertip whose skin ends
/// where its distal bone does (hand_shape.hpp; the model's skin and the simulated user's both do).
///
/// A digit seen tilted by φ toward or away from the camera shows the fingertip's rounded end
/// beyond the axis's own end: for an end of radius ρ the outline's farthest point lies ρ (1/cos φ
/// − 1) further along the axis, which is taken off with the model's distal radius.
///
/// A digit is no evidence, and gives no sample, when:
/// - its string is not measured, or the fit's cap is more than `max_cap_miss_m` from it (the fit
///   does not hold that digit, so its axis is not the finger's);
/// - its distal phalanx is tilted more than `max_tilt_rad` out of the image plane (the end is then
///   the pad's outline, not the tip's);
/// - the cap's projection is outside the image or off the matte;
/// - the walk leaves the image or does not end within `max_reach_m` (the finger runs into another
///   finger or the other hand), or ends nearer than `min_reach_m`;
/// - the walk, beyond where the model's fingertip begins to round off, passes more than
///   `max_overlap_px` inside another part of the hand's fitted outline, or ends within
///   `min_clearance_px` of one (`outline`, when given: the end may be a neighbour's edge, a thumb's
///   in a pinch);
/// - it is the thumb's, unless `thumb` (on the simulated rig the thumbs' read 1.5 mm short of the
///   fingers' in the Rubik's grasp, where the fingers' agree within 0.3 mm).
#include <opencv2/core/mat.hpp>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

struct FingertipEndParams {
  double max_tilt_rad = 0.6;       ///< the distal axis out of the image plane, at most [rad]
  double max_cap_miss_m = 0.003;   ///< the fit's cap from the string's, at most [m]
  double min_reach_m = 0.002;      ///< the fingertip beyond its cap, at least [m]
  double max_reach_m = 0.02;       ///< ... at most [m]
  double min_clearance_px = 0.0;   ///< the end outside every other part of the outline by this [px]
  /// The walk beyond the fingertip's base inside another part by at most this [px] (a fitted
  /// neighbour's outline overlaps a real fingertip's by a pixel or two; a finger the walk runs
  /// through is a capsule's breadth deep).
  double max_overlap_px = 3.0;
  bool thumb = false;              ///< measure the thumb too
};

/// One digit's measurement.
struct FingertipEnd {
  int finger = 0;           ///< thumb, index, middle or ring (hand::Finger)
  double reach_m = 0;       ///< the fingertip's end beyond the cap's centre, along the distal axis [m]
  double tilt_rad = 0;      ///< the distal axis's angle out of the image plane [rad]
  Vec2 cap_px = Vec2::Zero();  ///< the cap's projection [px]
  Vec2 end_px = Vec2::Zero();  ///< the outline's end found [px]
};

/// The fingertips' ends of hand `model` at its fitted pose `q` (see the file comment): one sample
/// per measured digit that passes the checks. `alpha`: the matte, CV_32FC1 in [0, 1] or CV_8UC1
/// read as /255; `threshold` on it. `outline` (optional): the hand's outline at q (project_hand).
std::vector<FingertipEnd> fingertip_ends(const hand::HandModel& model, const hand::HandParams& q,
                                         const HandObservation& observation, const vision::Camera& camera,
                                         const cv::Mat& alpha, double threshold,
                                         const FingertipEndParams& params = {},
                                         const ProjectedHand* outline = nullptr);

/// The fingertip's reach beyond the cap that the model predicts for a digit: −fingertip_offset.y
/// (the cap's centre lies that far back from the distal bone's end, along the bone) [m].
inline double model_fingertip_reach_m(const hand::HandModel& model) {
  return -model.shape.dimensions.fingertip_offset.y();
}

}  // namespace spidar::registration
