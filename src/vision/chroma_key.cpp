#include "spidar/vision/chroma_key.hpp"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

namespace spidar::vision {

Status validate(const ChromaKeyParams& p) {
  if (!(p.s_foreground >= -1.0 && p.s_foreground < p.s_background && p.s_background <= 1.0)) {
    return Error{"chroma key: s_foreground: expected -1 <= s_foreground < s_background <= 1, got " +
                 core::number_for_message(p.s_foreground) + " and " + core::number_for_message(p.s_background)};
  }
  if (!(p.dark_floor >= 1.0 && p.dark_floor <= 255.0)) {
    return Error{"chroma key: dark_floor: expected 1..255, got " + core::number_for_message(p.dark_floor)};
  }
  if (!(p.silhouette_threshold > 0.0 && p.silhouette_threshold < 1.0)) {
    return Error{"chroma key: silhouette_threshold: expected a value in (0, 1), got " +
                 core::number_for_message(p.silhouette_threshold)};
  }
  if (p.cleanup_radius_px < 0 || p.cleanup_radius_px > kMaxCleanupRadius_px) {
    return Error{"chroma key: cleanup_radius_px: expected 0.." + std::to_string(kMaxCleanupRadius_px) + ", got " +
                 std::to_string(p.cleanup_radius_px)};
  }
  if (!(p.spill_limit >= 0.5 && p.spill_limit <= 2.0)) {
    return Error{"chroma key: spill_limit: expected 0.5..2, got " + core::number_for_message(p.spill_limit)};
  }
  return Ok{};
}

ChromaKeyParams parse_chroma_key_params(const core::ConfigNode& node) {
  node.expect_keys({"s_foreground", "s_background", "dark_floor", "silhouette_threshold",
                    "cleanup_radius_px", "despill", "spill_limit"});
  ChromaKeyParams p;
  p.s_foreground = node.get_double("s_foreground", p.s_foreground);
  p.s_background = node.get_double("s_background", p.s_background);
  p.dark_floor = node.get_double("dark_floor", p.dark_floor);
  p.silhouette_threshold = node.get_double("silhouette_threshold", p.silhouette_threshold);
  if (auto c = node.find("cleanup_radius_px"))
    p.cleanup_radius_px = static_cast<int>(core::require_int_in_range(*c, 0, kMaxCleanupRadius_px));
  if (auto d = node.find("despill")) p.despill = d->as_bool();
  p.spill_limit = node.get_double("spill_limit", p.spill_limit);
  if (auto s = validate(p); !s.ok()) core::fail_at_named_key(node, s.error().message, "chroma key: ");
  return p;
}

Result<ChromaKeyer> ChromaKeyer::create(const ChromaKeyParams& p) {
  if (auto s = validate(p); !s.ok()) return s.error();
  ChromaKeyer k;
  k.params_ = p;
  k.lut_.resize(256 * 256);
  const double range = p.s_background - p.s_foreground;
  for (int b = 0; b < 256; ++b) {
    for (int rg = 0; rg < 256; ++rg) {
      const double denom = std::max({static_cast<double>(rg), static_cast<double>(b), p.dark_floor});
      const double s = (b - rg) / denom;
      const double alpha = std::clamp((p.s_background - s) / range, 0.0, 1.0);
      k.lut_[static_cast<std::size_t>(b * 256 + rg)] = static_cast<std::uint8_t>(std::lround(255.0 * alpha));
    }
  }
  k.silhouette_min_ = static_cast<std::uint8_t>(std::ceil(255.0 * p.silhouette_threshold - 1e-9));
  return k;
}

Status chroma_key(const cv::Mat& bgr, const ChromaKeyParams& p, ChromaKeyResult* out) {
  auto keyer = ChromaKeyer::create(p);
  if (!keyer) return keyer.error();
  return keyer->apply(bgr, out);
}

Status ChromaKeyer::apply(const cv::Mat& bgr, ChromaKeyResult* out) const {
  const ChromaKeyParams& p = params_;
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    return Error{"chroma key: expected a non-empty 8-bit BGR frame (CV_8UC3), got type " +
                 std::to_string(bgr.type()) + " size " + std::to_string(bgr.cols) + "x" +
                 std::to_string(bgr.rows)};
  }
  const int rows = bgr.rows, cols = bgr.cols;
  out->alpha.create(rows, cols, CV_32FC1);
  out->silhouette.create(rows, cols, CV_8UC1);
  float to_alpha[256];
  for (int i = 0; i < 256; ++i) to_alpha[i] = static_cast<float>(i) / 255.0f;
  const std::uint8_t* lut = lut_.data();
  const std::uint8_t sil_min = silhouette_min_;
  for (int y = 0; y < rows; ++y) {
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(y);
    float* a = out->alpha.ptr<float>(y);
    std::uint8_t* sil = out->silhouette.ptr<std::uint8_t>(y);
    for (int x = 0; x < cols; ++x) {
      const unsigned b = px[3 * x], g = px[3 * x + 1], r = px[3 * x + 2];
      const std::uint8_t q = lut[(b << 8) | (r > g ? r : g)];
      a[x] = to_alpha[q];
      sil[x] = q >= sil_min ? 255 : 0;
    }
  }
  if (p.cleanup_radius_px > 0) {
    const int k = 2 * p.cleanup_radius_px + 1;
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k));
    cv::morphologyEx(out->silhouette, out->silhouette, cv::MORPH_OPEN, kernel);
    cv::morphologyEx(out->silhouette, out->silhouette, cv::MORPH_CLOSE, kernel);
  }
  if (p.despill) {
    bgr.copyTo(out->foreground);
    const float limit = static_cast<float>(p.spill_limit);
    // Edge band: soft pixels (0 < alpha < 1) and their 8 neighbours that are not screen.
    // Soft pixels are few, so visit them and cap their neighbourhoods (capping is idempotent).
    for (int y = 0; y < rows; ++y) {
      const float* a = out->alpha.ptr<float>(y);
      for (int x = 0; x < cols; ++x) {
        if (!(a[x] > 0.0f && a[x] < 1.0f)) continue;
        for (int yy = std::max(y - 1, 0); yy <= std::min(y + 1, rows - 1); ++yy) {
          const float* an = out->alpha.ptr<float>(yy);
          std::uint8_t* px = out->foreground.ptr<std::uint8_t>(yy);
          for (int xx = std::max(x - 1, 0); xx <= std::min(x + 1, cols - 1); ++xx) {
            if (an[xx] <= 0.0f) continue;  // screen pixels are not part of the foreground
            const float rg = std::max<float>(px[3 * xx + 1], px[3 * xx + 2]);
            const float cap = std::min(255.0f, limit * rg);
            if (px[3 * xx] > cap) px[3 * xx] = static_cast<std::uint8_t>(cap);
          }
        }
      }
    }
  }
  return Ok{};
}

}  // namespace spidar::vision
