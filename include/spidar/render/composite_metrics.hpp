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

/// 100 · |{p ∈ region : (alpha(p) ≥ 0.5) ≠ truth(p)}| / |region| [%], with `alpha` a composite's
/// CV_32FC1 share of the real image, `truth` from truth_composite_mask and `region` CV_8UC1.
/// 0 for an empty region. Error on mismatched sizes or types.
Result<double> occlusion_error_pct(const cv::Mat& alpha, const cv::Mat& truth, const cv::Mat& region);

}  // namespace spidar::render
