#pragma once
/// The red wrist bracelets: per hand, the projected wrist [px] with a confidence.
///
/// Red pixels are those whose OpenCV HSV (8-bit: H 0..179, S and V 0..255) satisfies
///   (H ≤ hue_low_max or H ≥ hue_high_min), S ≥ saturation_min, V ≥ value_min,
/// i.e. two hue ranges because red wraps around hue 0 (evaluated directly on BGR, same result as
/// cv::cvtColor + cv::inRange up to rounding). Connected red pieces larger than min_area_px form
/// candidates; pieces separated by less than merge_gap_px (a finger lying across the band) are
/// merged when together they are about as thin as the thicker piece (two hands' bands side by
/// side are not one band). As in the paper, a candidate's projected wrist is the midpoint of the marker's two
/// ends along its principal axis (the band's long axis across the wrist).
///
/// Assignment to hands (index 0 = left, 1 = right): with predicted wrists, the joint assignment of
/// bands to both hands that best matches the predicted positions (within
/// max_prediction_distance_px) and band directions, leaving out a hand whose choice is ambiguous; without predictions, or when a
/// hand's prediction found nothing, by image side among the bands no prediction claims (the
/// camera looks over the user's hands, so the left hand is on the image's left; a fallback after
/// a failed prediction has its confidence scaled by 0.7).
/// Anything ambiguous is left unassigned (found = false): a hand may be reported missing, but
/// never with the other hand's bracelet.
///
/// Confidence in [0, 1]: 1 for a whole, unoccluded band of the expected length. It drops when
/// the band looks shorter than expected (partly hidden or cut by the image border), when it is
/// ragged (low fill of its oriented box), or touches the image border. The expected length is,
/// in order: the prediction's length_px for that hand, params.expected_length_px, the longest
/// band in the frame that looks whole by its aspect ratio, else expected_aspect × thickness.
#include <array>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"

namespace spidar::vision {

struct BraceletParams {
  int hue_low_max = 10;       ///< first red range: H in [0, hue_low_max] (OpenCV hue, 0..179)
  int hue_high_min = 170;     ///< second red range: H in [hue_high_min, 179]
  int saturation_min = 130;   ///< 0..255; skin is ~60..120, a red band ~180..255
  int value_min = 50;         ///< 0..255
  int min_area_px = 40;       ///< smaller red pieces are noise
  double merge_gap_px = 12;   ///< pieces whose boxes are closer than this are one bracelet
  /// Long side of a fully visible band [px]. 0: judge completeness by the band's aspect ratio
  /// instead (expected_aspect = length / thickness).
  double expected_length_px = 0;
  double expected_aspect = 2.5;
  double max_prediction_distance_px = 80;  ///< a candidate farther from the prediction is ignored
  /// A hand is left without a band when another choice of band for it costs less than this more
  /// (costs are squared σ-distances, see detect_bracelets).
  double ambiguity_margin = 1.0;
  double centre_margin_px = 16;  ///< without predictions, a lone candidate this near the midline is ambiguous
  bool left_hand_on_image_left = true;
};

Status validate(const BraceletParams& params);
/// Reads a `bracelet:` map (every key optional). Throws core::ConfigError.
BraceletParams parse_bracelet_params(const core::ConfigNode& node);

struct BraceletObservation {
  bool found = false;
  Vec2 wrist_px = Vec2::Zero();  ///< midpoint of the two ends [px]
  Vec2 end_a_px = Vec2::Zero();  ///< the ends along the principal axis [px]
  Vec2 end_b_px = Vec2::Zero();
  double length_px = 0;          ///< extent along the principal axis [px]
  double thickness_px = 0;       ///< extent across it [px]
  /// Where the red lies across the band, as a crescent's bulge: the red's centroid minus the
  /// middle of its extent across the long axis, along the unit across = (−u_y, u_x) for u the unit
  /// from end_a_px to end_b_px [px]. About +0.28 × thickness for a thin arc whose apex lies on the
  /// +across side, 0 for a straight strip or a whole ring (a band seen obliquely shows its near side,
  /// a crescent, and its bulge tells toward which side the forearm tilts).
  double bulge_px = 0;
  double fill = 0;               ///< share of its oriented box (length × thickness) that is red, 0..1
  int area_px = 0;
  int pieces = 0;                ///< connected red pieces merged into this bracelet
  double confidence = 0;         ///< 0..1
};

/// A bracelet candidate before assignment (exposed for tests and debugging views).
struct BraceletCandidate {
  BraceletObservation observation;  ///< confidence judged against params' expected length
  Vec2 centroid_px = Vec2::Zero();
  bool touches_border = false;
};

/// The confidence of a candidate for a band expected to be `expected_length_px` long (0: by
/// params.expected_aspect).
double bracelet_confidence(const BraceletCandidate& c, const BraceletParams& params,
                           double expected_length_px);

struct BraceletPrediction {
  std::array<std::optional<Vec2>, 2> wrist_px;  ///< predicted projected wrists (left, right)
  /// Predicted direction of each band's long axis in the image (across the forearm; sign free).
  std::array<std::optional<Vec2>, 2> axis_px;
  /// Predicted band length per hand [px] (e.g. the projected wrist width); 0 = use params.
  std::array<double, 2> length_px{0.0, 0.0};
};

/// Reusable buffers, so that per-frame detection does not allocate after the first frame.
struct BraceletWorkspace {
  cv::Mat mask, stats, centroids;
  cv::Mat labels;         ///< the labels of the red pixels' bounding box (a view of labels_buffer)
  cv::Mat labels_buffer;  ///< frame-sized
  std::vector<BraceletCandidate> candidates;
};

/// Unit direction of the major (long) axis of a pixel set whose covariance is `cov` [px²]: the
/// detector's axis of a band, which the registration's bracelet midpoint mirrors.
Vec2 major_axis(const Eigen::Matrix2d& cov);

/// The red mask (CV_8UC1, 255 = red) of an 8-bit BGR frame.
Status red_mask(const cv::Mat& bgr, const BraceletParams& params, cv::Mat* mask);

/// Bracelet candidates in a red mask, best first. With an expected band length (else
/// params.expected_length_px), pieces do not merge into anything longer than 1.5 times it.
void find_bracelet_candidates(const cv::Mat& mask, const BraceletParams& params,
                              BraceletWorkspace* ws, double expected_length_px = 0);

/// Both hands' bracelets (index 0 = left, 1 = right). Error on a bad frame or params.
Result<std::array<BraceletObservation, 2>> detect_bracelets(
    const cv::Mat& bgr, const BraceletParams& params, const BraceletPrediction* prediction,
    BraceletWorkspace* ws);

}  // namespace spidar::vision
