#include "spidar/render/composite_metrics.hpp"

#include <cmath>
#include <opencv2/core.hpp>

namespace spidar::render {

Status truth_composite_mask(const cv::Mat& mask, const cv::Mat& depth, const cv::Mat& scene,
                            cv::Mat* out) {
  if (out == nullptr) return Error{"truth_composite_mask: no output given"};
  if (mask.type() != CV_8UC1 || depth.type() != CV_32FC1 || scene.type() != CV_32FC1 ||
      mask.size() != depth.size() || mask.size() != scene.size())
    return Error{"truth_composite_mask: expected a CV_8UC1 mask and two CV_32FC1 depths of one size"};
  out->create(mask.size(), CV_8UC1);
  for (int y = 0; y < mask.rows; ++y) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const float* d = depth.ptr<float>(y);
    const float* s = scene.ptr<float>(y);
    std::uint8_t* o = out->ptr<std::uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x) o[x] = m[x] != 0 && d[x] < s[x] ? 255 : 0;
  }
  return Ok{};
}

Result<RegionDisagreement> region_disagreement(const cv::Mat& alpha, const cv::Mat& truth,
                                               const cv::Mat& region) {
  if (alpha.type() != CV_32FC1 || truth.type() != CV_8UC1 || region.type() != CV_8UC1 ||
      alpha.size() != truth.size() || alpha.size() != region.size())
    return Error{"region_disagreement: expected CV_32FC1 alpha, CV_8UC1 truth and region of one size"};
  RegionDisagreement d;
  // Branch-free, so that the compiler vectorises the row (the scorer calls this four times per
  // frame on the whole image, where most pixels are outside the region).
  for (int y = 0; y < alpha.rows; ++y) {
    const float* a = alpha.ptr<float>(y);
    const std::uint8_t* t = truth.ptr<std::uint8_t>(y);
    const std::uint8_t* r = region.ptr<std::uint8_t>(y);
    std::int32_t pixels = 0, wrong = 0;
    for (int x = 0; x < alpha.cols; ++x) {
      const std::int32_t in = r[x] != 0;
      pixels += in;
      wrong += in & static_cast<std::int32_t>((a[x] >= 0.5f) != (t[x] != 0));
    }
    d.pixels += pixels;
    d.wrong += wrong;
  }
  return d;
}

Status contested_mask(const cv::Mat& real_mask, const cv::Mat& scene_depth, cv::Mat* out) {
  if (out == nullptr) return Error{"contested_mask: no output given"};
  if (real_mask.type() != CV_8UC1 || scene_depth.type() != CV_32FC1 ||
      real_mask.size() != scene_depth.size())
    return Error{"contested_mask: expected a CV_8UC1 mask and a CV_32FC1 depth of one size"};
  out->create(real_mask.size(), CV_8UC1);
  for (int y = 0; y < real_mask.rows; ++y) {
    const std::uint8_t* m = real_mask.ptr<std::uint8_t>(y);
    const float* s = scene_depth.ptr<float>(y);
    std::uint8_t* o = out->ptr<std::uint8_t>(y);
    for (int x = 0; x < real_mask.cols; ++x) o[x] = m[x] != 0 && std::isfinite(s[x]) ? 255 : 0;
  }
  return Ok{};
}

Result<double> occlusion_error_pct(const cv::Mat& alpha, const cv::Mat& truth, const cv::Mat& region) {
  auto d = region_disagreement(alpha, truth, region);
  if (!d) return Error{"occlusion_error_pct: expected CV_32FC1 alpha, CV_8UC1 truth and region of one size"};
  return d->pct();
}

}  // namespace spidar::render
