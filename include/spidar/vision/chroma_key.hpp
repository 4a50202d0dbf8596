#pragma once
/// Chroma key: a soft matte of the hands against the blue screen.
///
/// Each pixel's *blue dominance* s = (B − max(R, G)) / max(R, G, B, dark_floor) lies in [−1, 1]
/// and does not change when the light on it gets brighter or dimmer (all three channels scale
/// together), so shading, uneven lighting and the hands' own shadows on the screen do not move
/// the key. Blue screen: s ≈ 0.5–0.8; skin (R > G > B): s ≈ −0.5…−0.2. The matte is
///   alpha = clamp((s_background − s) / (s_background − s_foreground), 0, 1)   (1 = hand),
/// the silhouette is alpha ≥ silhouette_threshold (after an optional small morphological
/// clean-up), and on the edge band (0 < alpha < 1, grown by one pixel) blue spill is removed
/// from the colour: B ← min(B, spill_limit · max(R, G)).
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "spidar/core/config.hpp"
#include "spidar/core/result.hpp"

namespace spidar::vision {

/// The largest ChromaKeyParams::cleanup_radius_px [px].
inline constexpr int kMaxCleanupRadius_px = 10;

struct ChromaKeyParams {
  double s_foreground = 0.10;   ///< s at or below this: alpha = 1 (hand)
  double s_background = 0.35;   ///< s at or above this: alpha = 0 (screen)
  double dark_floor = 20.0;     ///< [0..255] brightness floor of the denominator (damps noise)
  double silhouette_threshold = 0.5;  ///< alpha at or above this: silhouette pixel
  int cleanup_radius_px = 1;    ///< radius of an opening then closing of the silhouette; 0 = off
  bool despill = true;          ///< write `foreground` with blue spill removed on the edge band
  double spill_limit = 1.0;     ///< B ≤ spill_limit · max(R, G) on the edge band
  bool operator==(const ChromaKeyParams&) const = default;
};

/// Checks ranges (s_foreground < s_background within [−1, 1], thresholds in (0, 1), ...).
Status validate(const ChromaKeyParams& params);
/// Reads a `chroma_key:` map (every key optional; defaults above). Throws core::ConfigError.
ChromaKeyParams parse_chroma_key_params(const core::ConfigNode& node);

struct ChromaKeyResult {
  cv::Mat alpha;       ///< CV_32FC1, 0..1, 1 = hand
  cv::Mat silhouette;  ///< CV_8UC1, 255 = hand, 0 = screen
  cv::Mat foreground;  ///< CV_8UC3, the frame with spill removed on edges (if params.despill)
};

/// A chroma keyer for fixed params: the matte depends only on (B, max(R, G)), so it is
/// tabulated once (64 KiB, alpha quantised to 1/255 like the 8-bit input) and each frame is
/// one table look-up per pixel.
class ChromaKeyer {
 public:
  /// Error if the params are invalid.
  static Result<ChromaKeyer> create(const ChromaKeyParams& params);
  const ChromaKeyParams& params() const { return params_; }
  /// Keys an 8-bit BGR frame. Reuses the buffers in `out` when their sizes fit (no allocation
  /// per frame after the first). Error on an empty or non-8UC3 frame.
  Status apply(const cv::Mat& bgr, ChromaKeyResult* out) const;

 private:
  ChromaKeyer() = default;
  ChromaKeyParams params_;
  std::vector<std::uint8_t> lut_;  ///< [B · 256 + max(R, G)] → round(255 · alpha)
  std::uint8_t silhouette_min_ = 128;  ///< quantised alpha at or above: silhouette
};

/// One-off keying (builds the table each call; use ChromaKeyer per stream).
Status chroma_key(const cv::Mat& bgr, const ChromaKeyParams& params, ChromaKeyResult* out);

}  // namespace spidar::vision
