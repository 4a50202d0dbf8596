#include "spidar/vision/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <string>

namespace spidar::vision {

Status silhouette_distance(const cv::Mat& silhouette, SilhouetteDistance* out,
                           const SilhouetteDistanceOptions& options) {
  if (silhouette.empty() || silhouette.type() != CV_8UC1) {
    return Error{"silhouette distance: expected a non-empty CV_8UC1 silhouette"};
  }
  const int max_distance_px = options.max_distance_px;
  if (max_distance_px < 0) return Error{"silhouette distance: expected max_distance_px >= 0"};
  if (options.downsample != 1 && options.downsample != 2) {
    return Error{"silhouette distance: downsample: expected 1 or 2, got " +
                 std::to_string(options.downsample)};
  }
  out->scale = options.downsample;
  const cv::Rect image(0, 0, silhouette.cols, silhouette.rows);
  const cv::Rect box = cv::boundingRect(silhouette);
  out->empty = box.area() == 0;
  if (out->empty) {
    out->roi = image;
    out->distance.create(silhouette.size(), CV_32FC1);
    out->distance.setTo(std::numeric_limits<float>::infinity());
    out->labels.create(silhouette.size(), CV_32SC1);
    out->labels.setTo(0);
    out->label_pixel.assign(1, cv::Point(-1, -1));
    return Ok{};
  }
  const int m = max_distance_px;
  out->roi = m == 0 ? image
                    : (cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) & image);
  cv::Mat sil = silhouette(out->roi);
  if (out->scale == 2) {
    sil.copyTo(out->silhouette_roi);
    // A 2×2 block is silhouette if any of its pixels is (blocks at an odd edge are 1 wide).
    cv::Mat& half = out->scratch_half;
    half.create((sil.rows + 1) / 2, (sil.cols + 1) / 2, CV_8UC1);
    for (int y = 0; y < half.rows; ++y) {
      const std::uint8_t* a = sil.ptr<std::uint8_t>(2 * y);
      const std::uint8_t* b = sil.ptr<std::uint8_t>(std::min(2 * y + 1, sil.rows - 1));
      std::uint8_t* h = half.ptr<std::uint8_t>(y);
      for (int x = 0; x < half.cols; ++x) {
        const int x1 = std::min(2 * x + 1, sil.cols - 1);
        h[x] = (a[2 * x] | a[x1] | b[2 * x] | b[x1]) ? 255 : 0;
      }
    }
    sil = half;
  }
  // distanceTransform measures the distance to the nearest *zero* pixel: silhouette → 0.
  cv::Mat& inverted = out->scratch_inverted;
  cv::compare(sil, 0, inverted, cv::CMP_EQ);
  cv::distanceTransform(inverted, out->distance, out->labels, cv::DIST_L2, cv::DIST_MASK_5,
                        cv::DIST_LABEL_PIXEL);
  // Each silhouette pixel carries its own label (1, 2, ... in OpenCV's order): read the table
  // back from the image, sized for one label per pixel up front (grown if ever needed).
  out->label_pixel.assign(static_cast<std::size_t>(cv::countNonZero(sil)) + 1, cv::Point(-1, -1));
  for (int y = 0; y < sil.rows; ++y) {
    const std::uint8_t* s = sil.ptr<std::uint8_t>(y);
    const int* lab = out->labels.ptr<int>(y);
    for (int x = 0; x < sil.cols; ++x) {
      if (!s[x]) continue;
      const auto l = static_cast<std::size_t>(lab[x]);
      if (l >= out->label_pixel.size()) out->label_pixel.resize(l + 1, cv::Point(-1, -1));
      out->label_pixel[l] = {out->scale * x + out->roi.x, out->scale * y + out->roi.y};
    }
  }
  return Ok{};
}

std::optional<cv::Point> SilhouetteDistance::nearest(int x, int y) const {
  if (empty || !roi.contains(cv::Point(x, y))) return std::nullopt;
  const int l = labels.at<int>((y - roi.y) / scale, (x - roi.x) / scale);
  if (l <= 0 || l >= static_cast<int>(label_pixel.size())) return std::nullopt;
  const cv::Point block = label_pixel[l];
  if (block.x < 0) return std::nullopt;
  if (scale == 1) return block;
  // The silhouette pixel of the nearest block that is nearest to (x, y).
  std::optional<cv::Point> best;
  int best_d2 = 0;
  for (int dy = 0; dy < scale; ++dy) {
    for (int dx = 0; dx < scale; ++dx) {
      const cv::Point q(block.x + dx, block.y + dy);
      if (q.x >= roi.x + roi.width || q.y >= roi.y + roi.height) continue;
      if (!silhouette_roi.at<std::uint8_t>(q.y - roi.y, q.x - roi.x)) continue;
      const int d2 = (q.x - x) * (q.x - x) + (q.y - y) * (q.y - y);
      if (!best || d2 < best_d2) {
        best = q;
        best_d2 = d2;
      }
    }
  }
  return best;
}

std::optional<Vec2> SilhouetteDistance::nearest(const Vec2& uv) const {
  if (empty || !uv.allFinite()) return std::nullopt;
  const double fx = std::clamp(uv.x(), -1e9, 1e9), fy = std::clamp(uv.y(), -1e9, 1e9);
  const int x = std::clamp(static_cast<int>(std::lround(fx)), roi.x, roi.x + roi.width - 1);
  const int y = std::clamp(static_cast<int>(std::lround(fy)), roi.y, roi.y + roi.height - 1);
  const auto p = nearest(x, y);
  if (!p) return std::nullopt;
  return Vec2(p->x, p->y);
}

double SilhouetteDistance::distance_at(const Vec2& uv) const {
  const auto p = nearest(uv);
  if (!p) return std::numeric_limits<double>::infinity();
  return (*p - uv).norm();
}

double sample_bilinear(const cv::Mat& alpha, const Vec2& uv) {
  const bool bytes = alpha.type() == CV_8UC1;
  if (alpha.empty() || (alpha.type() != CV_32FC1 && !bytes) || !uv.allFinite()) return 0.0;
  const double fx = std::floor(uv.x()), fy = std::floor(uv.y());
  if (fx < -1.0 || fy < -1.0 || fx > alpha.cols || fy > alpha.rows) return 0.0;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const double ax = uv.x() - fx, ay = uv.y() - fy;
  auto at = [&](int x, int y) -> double {
    if (x < 0 || y < 0 || x >= alpha.cols || y >= alpha.rows) return 0.0;
    return bytes ? alpha.at<std::uint8_t>(y, x) / 255.0 : static_cast<double>(alpha.at<float>(y, x));
  };
  return (1 - ay) * ((1 - ax) * at(x0, y0) + ax * at(x0 + 1, y0)) +
         ay * ((1 - ax) * at(x0, y0 + 1) + ax * at(x0 + 1, y0 + 1));
}

double sample_nearest(const cv::Mat& alpha, const Vec2& uv) {
  const bool bytes = alpha.type() == CV_8UC1;
  if (alpha.empty() || (alpha.type() != CV_32FC1 && !bytes) || !uv.allFinite()) return 0.0;
  const double fx = std::round(uv.x()), fy = std::round(uv.y());
  if (fx < 0.0 || fy < 0.0 || fx >= alpha.cols || fy >= alpha.rows) return 0.0;
  const int x = static_cast<int>(fx), y = static_cast<int>(fy);
  return bytes ? alpha.at<std::uint8_t>(y, x) / 255.0 : static_cast<double>(alpha.at<float>(y, x));
}

}  // namespace spidar::vision
