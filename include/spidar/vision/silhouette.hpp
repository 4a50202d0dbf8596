#pragma once
/// Silhouette utilities for registration: the distance transform with the nearest silhouette
/// pixel of every pixel (pulls model pixels outside the real silhouette onto it), and sampling
/// of the soft matte at sub-pixel points (the paper's joint-balls, eq. 21, ask whether a
/// projected point lies on the real hand's silhouette).
///
/// Pixel coordinates follow the camera convention: (0, 0) is the centre of the top-left pixel.
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"

namespace spidar::vision {

/// Distances to, and the nearest pixel of, a binary silhouette (cv::distanceTransform, L2 with
/// the 5×5 mask and DIST_LABEL_PIXEL; the labels are mapped back to pixel coordinates).
///
/// The transform covers `roi`: the whole image, or with max_distance_px > 0 the silhouette's
/// bounding box grown by that margin (registration only pulls model pixels that lie near the
/// hands; this saves most of the cost). Queries outside the roi are clamped into it first, so
/// they still get a silhouette pixel, though not necessarily the nearest one.
///
/// With downsample = 2 the transform runs on a half-resolution silhouette (a 2×2 block is
/// silhouette if any of its pixels is) and a query picks, in the nearest block, the silhouette
/// pixel nearest to it: about 4× cheaper, and the returned pixel is at most ~2 px farther than
/// the true nearest one. `nearest` and `distance_at` always answer in full-resolution pixels.
struct SilhouetteDistanceOptions {
  int max_distance_px = 0;  ///< margin around the silhouette's bounding box [px]; 0 = whole image
  int downsample = 1;       ///< 1 (exact labels up to OpenCV's mask) or 2 (half resolution)
};

struct SilhouetteDistance {
  cv::Rect roi;      ///< region covered, in full-resolution image pixels
  int scale = 1;     ///< 1 or 2: pixels of the maps below per image pixel side
  cv::Mat distance;  ///< CV_32FC1 over roi/scale [map px], 0 on the silhouette (5×5 mask approx.)
  cv::Mat labels;    ///< CV_32SC1 over roi/scale, OpenCV's label of the nearest silhouette pixel
  std::vector<cv::Point> label_pixel;  ///< label → its map pixel as image (x, y) of the block's
                                       ///< top-left; entry 0 unused
  cv::Mat silhouette_roi;  ///< full-resolution silhouette over roi (scale 2 only)
  bool empty = true;  ///< no silhouette pixel at all
  cv::Mat scratch_half, scratch_inverted;  ///< working images, reused between calls

  /// The silhouette pixel nearest to image pixel (x, y) (inside the roi), or nullopt if empty
  /// or outside the roi.
  std::optional<cv::Point> nearest(int x, int y) const;
  /// The silhouette pixel nearest to a sub-pixel point [px]: looked up at the nearest pixel,
  /// clamped into the roi. nullopt if the silhouette is empty.
  std::optional<Vec2> nearest(const Vec2& uv) const;
  /// Distance [px] to the silhouette at a sub-pixel point: exact Euclidean distance to the
  /// looked-up nearest pixel; +inf if the silhouette is empty.
  double distance_at(const Vec2& uv) const;
};

/// Computes `out` from a CV_8UC1 silhouette (non-zero = silhouette). Reuses out's buffers.
Status silhouette_distance(const cv::Mat& silhouette, SilhouetteDistance* out,
                           const SilhouetteDistanceOptions& options = {});

/// Bilinear sample of a matte at a sub-pixel point [px]: a CV_32FC1 matte in [0, 1], or a CV_8UC1
/// one read as value / 255 (a binary silhouette, 255 = hand, samples exactly as its 0/1 float
/// copy would); pixels outside the image count as 0 (screen), so the value fades to 0 across the
/// border. 0 for any other type.
double sample_bilinear(const cv::Mat& alpha, const Vec2& uv);

/// The matte at the pixel nearest a sub-pixel point [px] (the same types and scaling as
/// sample_bilinear); 0 outside the image, for a non-finite point, or for any other type.
double sample_nearest(const cv::Mat& alpha, const Vec2& uv);

/// True if the matte at uv (bilinear) is at least `threshold`.
inline bool on_silhouette(const cv::Mat& alpha, const Vec2& uv, double threshold = 0.5) {
  return sample_bilinear(alpha, uv) >= threshold;
}

}  // namespace spidar::vision
