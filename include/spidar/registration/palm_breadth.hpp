#pragma once
/// The palm's breadth in the image: evidence on a hand's width for the shape estimator
/// (shape_estimator.hpp).
///
/// The strings measure four fingertips, which a narrower hand reaches as well by spreading its
/// fingers; the width is therefore weakly seen by them (a large user's estimate stayed 10 % narrow).
/// The palm seen face on shows it directly: its breadth across the hand, a little before the
/// knuckles, is the hand's breadth (the width is defined across the MCP joints, hand_shape.hpp),
/// whatever the skin's tissue around the fingers, webs and pads.
///
/// A chord is measured once, when a keyframe is taken, on the line through the model palm's
/// centre at `at` of the way from its wrist end to its knuckles, across the palm's projected long
/// axis. The silhouette is walked from that centre outward both ways until it ends. The model's
/// chord along the same image direction is the extent of the palm's cross-section at that level
/// (a stadium: the palm box's breadth, hand_shape.hpp's PalmBox, with its edges rounded by half
/// circles of its half thickness), projected with the camera. The estimator fits the model's
/// chord to the measured one. Only palms seen nearly face on are used, where the section's shape
/// matters least: tilted by 37° (min_facing 0.8) an ellipse's extent is 4 % below a stadium's,
/// face on both are the breadth.
///
/// A chord is no evidence, and is not taken, when:
/// - the palm is not seen face on (|n·v| < min_facing, n its normal, v the ray to its centre);
/// - its centre is not on the silhouette, or the line leaves the image;
/// - a digit (the thumb beside the palm's edge, a finger curled beside it), drawn at the fitted
///   pose, covers the line more than digit_clearance_px beyond the model palm's edges, where the
///   measured chord reached: it would lengthen the chord;
/// - a silhouette pixel on the chord belongs to the other hand or a forearm (the coverage
///   evidence's owners, coverage.hpp), when those are given;
/// - the measured chord differs from the model's by more than max_relative_change (a merged
///   outline the checks above missed).
#include <optional>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/coverage.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

struct PalmChordParams {
  double at = 0.85;                  ///< level along the palm: 0 its wrist end, 1 its knuckles
  double min_facing = 0.8;           ///< |cos| of the angle between the palm's normal and the ray
  double digit_clearance_px = 3.0;   ///< a digit on the line this far beyond the palm's edges spoils it [px]
  double max_relative_change = 0.3;  ///< |measured / model − 1| above this: not a chord of this palm
};

/// One measured chord (pixels of the camera's image).
struct PalmChord {
  double at = 0.85;         ///< the level it was measured at (PalmChordParams::at)
  Vec2 across_px = Vec2::Zero();  ///< unit image direction across the palm
  double measured_px = 0;   ///< the silhouette's chord along across_px
};

/// The model palm's breadth along image direction `across` (unit) at level `at` [px]: the
/// extent of its cross-section there (the file comment's stadium), projected with `camera`. 0 when part of it is behind the camera.
double model_palm_chord_px(const hand::HandModel& model, const hand::HandParams& q,
                           const vision::Camera& camera, double at, const Vec2& across);

/// Measures the chord of hand `model` at pose `q` in `silhouette` (CV_8UC1, non-zero = hand).
/// `owned` (null = not checked): the silhouette pixels this hand owns, sampled every
/// `owned_stride_px` from stride/2 (coverage_evidence). nullopt when the chord is no evidence
/// (see the file comment).
std::optional<PalmChord> measure_palm_chord(const hand::HandModel& model, const hand::HandParams& q,
                                            const vision::Camera& camera, const cv::Mat& silhouette,
                                            const std::vector<OwnedPixel>* owned, int owned_stride_px,
                                            const PalmChordParams& params = {});

}  // namespace spidar::registration
