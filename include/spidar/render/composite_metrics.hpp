#pragma once
/// How well a composite shows the real hands where they should be: the share of pixels, over a
/// region around the hands, where a composite's decision "real image here" differs from the
/// ground truth's.
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"

namespace spidar::render {

/// The ground truth's decision: the real hand is shown where it is in front of the scene.
/// `truth_mask` CV_8UC1 (non-zero = a real hand, bracelet or forearm in front of the screen),
/// `truth_depth` and `scene_depth` CV_32FC1 z_C [m] (+inf = nothing). Writes CV_8UC1 255/0.
Status truth_composite_mask(const cv::Mat& truth_mask, const cv::Mat& truth_depth,
                            const cv::Mat& scene_depth, cv::Mat* out);

/// Pixels of a region and how many of them a composite decides differently from the truth.
struct RegionDisagreement {
  long pixels = 0;  ///< |region|
  long wrong = 0;   ///< |{p ∈ region : (alpha(p) ≥ 0.5) ≠ truth(p)}|
  /// 100 · wrong / pixels [%]; 0 for an empty region.
  double pct() const { return pixels == 0 ? 0.0 : 100.0 * static_cast<double>(wrong) / static_cast<double>(pixels); }
};

/// Counts the region's pixels where `alpha` (CV_32FC1 share of the real image) decides "real
/// image here" (≥ 0.5) differently from `truth` (CV_8UC1, non-zero = real image). Error on
/// mismatched sizes or types.
Result<RegionDisagreement> region_disagreement(const cv::Mat& alpha, const cv::Mat& truth,
                                               const cv::Mat& region);

/// The contested pixels of a frame: where a real hand (`real_mask` CV_8UC1, non-zero) and a
/// virtual object (`scene_depth` CV_32FC1 z_C [m], finite = an object is drawn there, whatever
/// lies in front of it) overlap in the image. Only there does depth order decide what a
/// composite shows; everywhere else any compositor is right. Writes CV_8UC1 255/0.
Status contested_mask(const cv::Mat& real_mask, const cv::Mat& scene_depth, cv::Mat* out);

/// 100 · |{p ∈ region : (alpha(p) ≥ 0.5) ≠ truth(p)}| / |region| [%], with `alpha` a composite's
/// CV_32FC1 share of the real image, `truth` from truth_composite_mask and `region` CV_8UC1.
/// 0 for an empty region. Error on mismatched sizes or types.
Result<double> occlusion_error_pct(const cv::Mat& alpha, const cv::Mat& truth, const cv::Mat& region);

}  // namespace spidar::render
