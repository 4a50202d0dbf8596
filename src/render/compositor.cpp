#include "spidar/render/compositor.hpp"

#include <algorithm>
#include <cfloat>
#include <cstring>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

namespace spidar::render {

Result<CompositeMode> parse_composite_mode(const std::string& name) {
  if (name == "paper") return CompositeMode::kPaper;
  if (name == "depth") return CompositeMode::kDepth;
  return Error{"compositor mode: expected 'paper' or 'depth', got '" + name + "'"};
}

const char* composite_mode_name(CompositeMode mode) {
  return mode == CompositeMode::kPaper ? "paper" : "depth";
}

Status validate(const CompositorParams& p) {
  if (!(p.depth_margin_m >= 0 && p.depth_margin_m < 1))
    return Error{"compositor: depth_margin_m must be in [0, 1) m, got " +
                 std::to_string(p.depth_margin_m)};
  if (p.edge_blur_px < 0 || p.edge_blur_px > 16)
    return Error{"compositor: edge_blur_px must be in 0..16, got " + std::to_string(p.edge_blur_px)};
  if (p.carry_downsample != 1 && p.carry_downsample != 2)
    return Error{"compositor: carry_downsample must be 1 or 2, got " + std::to_string(p.carry_downsample)};
  if (p.max_carry_px < 1 || p.max_carry_px > 4096)
    return Error{"compositor: max_carry_px must be in 1..4096, got " +
                 std::to_string(p.max_carry_px)};
  return Ok{};
}

namespace {

Status check_inputs(const CompositeInputs& in, bool need_alpha) {
  if (in.virt == nullptr) return Error{"compositor: no rendering given (CompositeInputs::virt)"};
  const RenderTargets& v = *in.virt;
  if (v.colour.empty() || v.colour.type() != CV_8UC3)
    return Error{"compositor: rendering colour must be CV_8UC3 (read kColour)"};
  const cv::Size size = v.colour.size();
  if (v.depth.size() != size || v.depth.type() != CV_32FC1)
    return Error{"compositor: rendering depth must be CV_32FC1 of the colour's size (read kDepth)"};
  if (v.hand_depth.size() != size || v.hand_depth.type() != CV_32FC1)
    return Error{"compositor: rendering hand_depth must be CV_32FC1 of the colour's size (read "
                 "kHandDepth)"};
  if (in.real_bgr.size() != size || in.real_bgr.type() != CV_8UC3)
    return Error{"compositor: the real image must be CV_8UC3 of the rendering's size " +
                 std::to_string(size.width) + "x" + std::to_string(size.height) + ", got " +
                 std::to_string(in.real_bgr.cols) + "x" + std::to_string(in.real_bgr.rows)};
  if (need_alpha && (in.real_alpha.size() != size || in.real_alpha.type() != CV_32FC1))
    return Error{"compositor: depth mode needs the chroma-key matte (CV_32FC1, rendering's size)"};
  return Ok{};
}

/// One row of a composite: out = a · real + (1 − a) · virt per pixel of n (BGR, 8 bit), rounded;
/// a ≤ 0 gives virt and a = 1 real, exactly as the formula would. Runs of either are copied
/// whole (most of a row is one or the other; only the soft edges are blended).
void compose_row(const float* a, const std::uint8_t* real, const std::uint8_t* virt,
                 std::uint8_t* out, int n) {
  auto copy_run = [&](int x, int end, const std::uint8_t* from) {
    std::memcpy(out + 3 * x, from + 3 * x, 3 * static_cast<std::size_t>(end - x));
    return end;
  };
  int x = 0;
  while (x < n) {
    const float w = a[x];
    int end = x + 1;
    if (w <= 0.f) {
      while (end < n && a[end] <= 0.f) ++end;
      x = copy_run(x, end, virt);
    } else if (w == 1.f) {
      while (end < n && a[end] == 1.f) ++end;
      x = copy_run(x, end, real);
    } else {
      for (int c = 3 * x; c < 3 * x + 3; ++c) {
        const float value = w * real[c] + (1.f - w) * virt[c];
        out[c] = static_cast<std::uint8_t>(std::clamp(value + 0.5f, 0.f, 255.f));
      }
      ++x;
    }
  }
}

/// The whole composite, row by row: outside `roi` the rendering's colour with alpha 0; inside,
/// `alpha_row(y, a)` writes the alpha of image row y's roi columns to a[0 .. roi.width) and the
/// row is composed with it. One pass over each image: nothing is copied first.
template <class AlphaRow>
void compose_rows(const cv::Mat& virt, const cv::Mat& real, const cv::Rect& roi,
                  AlphaRow&& alpha_row, cv::Mat& out, cv::Mat& alpha) {
  out.create(virt.size(), CV_8UC3);
  alpha.create(virt.size(), CV_32FC1);
  const std::size_t row_bytes = 3 * static_cast<std::size_t>(virt.cols);
  for (int y = 0; y < virt.rows; ++y) {
    const std::uint8_t* v = virt.ptr<std::uint8_t>(y);
    std::uint8_t* o = out.ptr<std::uint8_t>(y);
    float* a = alpha.ptr<float>(y);
    if (y < roi.y || y >= roi.y + roi.height || roi.width <= 0) {
      std::memcpy(o, v, row_bytes);
      std::fill(a, a + virt.cols, 0.f);
      continue;
    }
    const int x0 = roi.x, x1 = roi.x + roi.width;
    std::memcpy(o, v, 3 * static_cast<std::size_t>(x0));
    std::memcpy(o + 3 * x1, v + 3 * x1, 3 * static_cast<std::size_t>(virt.cols - x1));
    std::fill(a, a + x0, 0.f);
    std::fill(a + x1, a + virt.cols, 0.f);
    alpha_row(y, a + x0);
    compose_row(a + x0, real.ptr<std::uint8_t>(y) + 3 * x0, v + 3 * x0, o + 3 * x0, roi.width);
  }
}

}  // namespace

Status Compositor::compose(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha) {
  if (out == nullptr) return Error{"compositor: no output given"};
  if (auto s = validate(params_); !s) return s;
  // The alpha goes to the caller's buffer, or to our own (not to one a caller lent last time).
  if (alpha == nullptr && alpha_shared_) alpha_ = cv::Mat();
  alpha_shared_ = alpha != nullptr;
  cv::Mat& a = alpha != nullptr ? *alpha : alpha_;
  auto st = params_.mode == CompositeMode::kPaper ? compose_paper(in, out, &a)
                                                  : compose_depth(in, out, &a);
  if (alpha != nullptr) alpha_ = *alpha;
  return st;
}

Status Compositor::compose_paper(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha) {
  if (auto s = check_inputs(in, false); !s) return s;
  const RenderTargets& v = *in.virt;
  // The real image wherever the virtual hand is front-most: only within the hands' box, where the
  // rendering says where that is (outside it the virtual image, alpha 0).
  const cv::Rect whole(0, 0, v.colour.cols, v.colour.rows);
  const cv::Rect roi = v.hand_box ? (*v.hand_box & whole) : whole;
  compose_rows(v.colour, in.real_bgr, roi,
               [&](int y, float* a) {
                 const float* hand = v.hand_depth.ptr<float>(y) + roi.x;
                 const float* depth = v.depth.ptr<float>(y) + roi.x;
                 for (int x = 0; x < roi.width; ++x) a[x] = hand[x] < depth[x] ? 1.f : 0.f;
               },
               *out, *alpha);
  return Ok{};
}

Status Compositor::carry_hand_depth(const RenderTargets& v, const cv::Rect& roi) {
  // Virtual-hand pixels, and for every pixel near them the nearest one (or the nearest 2×2 block
  // holding one: its blocks start at the distance transform's roi corner).
  cv::compare(v.hand_depth, FLT_MAX, hand_mask_, cv::CMP_LT);
  vision::SilhouetteDistanceOptions dt_options;
  dt_options.max_distance_px = params_.max_carry_px;  // only pixels the carry can reach
  dt_options.downsample = params_.carry_downsample;
  if (auto s = vision::silhouette_distance(hand_mask_, &distance_, dt_options); !s) return s;
  const auto unmatched = static_cast<std::uint8_t>(params_.show_unmatched ? 1 : 0);
  const auto margin = static_cast<float>(params_.depth_margin_m);
  const int sc = distance_.scale;
  const auto max_d = static_cast<float>(params_.max_carry_px) / static_cast<float>(sc);  // map units
  const cv::Rect& dt = distance_.roi;
  const int rows = v.hand_depth.rows, cols = v.hand_depth.cols;
  const float none = std::numeric_limits<float>::quiet_NaN();
  front_.create(roi.size(), CV_8UC1);
  if (distance_.empty) {
    front_.setTo(unmatched);
    return Ok{};
  }
  // Per map cell (a pixel, or a 2×2 block from the dt roi's corner) that a roi pixel falls in:
  // the depth carried there, the front-most hand depth of the nearest cell holding a
  // virtual-hand pixel; NaN: none in reach. Cells no roi pixel falls in are not computed.
  carried_.create(distance_.labels.size(), CV_32FC1);
  auto cell_range = [&](int from, int to, int origin, int cells) {  // image [from, to) → cells
    const int first = std::max(from, origin);
    if (first >= to) return cv::Range(0, 0);
    return cv::Range((first - origin) / sc, std::min((to - 1 - origin) / sc + 1, cells));
  };
  const cv::Range cell_rows = cell_range(roi.y, roi.y + roi.height, dt.y, carried_.rows);
  const cv::Range cell_cols = cell_range(roi.x, roi.x + roi.width, dt.x, carried_.cols);
  for (int ly = cell_rows.start; ly < cell_rows.end; ++ly) {
    const int* lab = distance_.labels.ptr<int>(ly);
    const float* dist = distance_.distance.ptr<float>(ly);
    float* c = carried_.ptr<float>(ly);
    for (int lx = cell_cols.start; lx < cell_cols.end; ++lx) {
      c[lx] = none;
      const int l = lab[lx];
      if (dist[lx] > max_d || l <= 0 || l >= static_cast<int>(distance_.label_pixel.size())) continue;
      const cv::Point q = distance_.label_pixel[static_cast<std::size_t>(l)];
      if (q.x < 0) continue;
      float d = FLT_MAX;
      for (int yy = q.y; yy < std::min(q.y + sc, rows); ++yy) {
        const float* hd = v.hand_depth.ptr<float>(yy);
        for (int xx = q.x; xx < std::min(q.x + sc, cols); ++xx) d = std::min(d, hd[xx]);
      }
      c[lx] = d;
    }
  }
  // Each pixel of the roi: its map column (−1 outside the map).
  map_column_.resize(static_cast<std::size_t>(roi.width));
  for (int x = 0; x < roi.width; ++x) {
    const int ix = x + roi.x;
    const int lx = ix >= dt.x ? (ix - dt.x) / sc : -1;
    map_column_[static_cast<std::size_t>(x)] = lx >= carried_.cols ? -1 : lx;
  }
  for (int y = 0; y < roi.height; ++y) {
    const int iy = y + roi.y;
    const float* depth = v.depth.ptr<float>(iy) + roi.x;
    std::uint8_t* f = front_.ptr<std::uint8_t>(y);
    const int ly = iy >= dt.y ? (iy - dt.y) / sc : -1;
    if (ly < 0 || ly >= carried_.rows) {
      std::fill(f, f + roi.width, unmatched);
      continue;
    }
    const float* c = carried_.ptr<float>(ly);
    for (int x = 0; x < roi.width; ++x) {
      const int lx = map_column_[static_cast<std::size_t>(x)];
      const float carried = lx >= 0 ? c[lx] : none;
      f[x] = std::isnan(carried) ? unmatched : (carried < depth[x] + margin ? 1 : 0);
    }
  }
  return Ok{};
}

Status Compositor::compose_depth(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha) {
  if (auto s = check_inputs(in, true); !s) return s;
  const RenderTargets& v = *in.virt;
  // Only where the matte is non-zero (and within the blur's reach of it) can anything change.
  const int r = params_.edge_blur_px;
  cv::compare(in.real_alpha, 0.f, hand_mask_, cv::CMP_GT);  // SIMD; faster than a scan of ours
  cv::Rect roi = cv::boundingRect(hand_mask_);
  if (roi.area() > 0) {
    const cv::Rect image(0, 0, v.colour.cols, v.colour.rows);
    roi = cv::Rect(roi.x - r, roi.y - r, roi.width + 2 * r, roi.height + 2 * r) & image;
    if (auto s = carry_hand_depth(v, roi); !s) return s;
    // The blurred occlusion mask, box of (2r + 1)² pixels with the roi's edges replicated: the
    // count of front pixels in each box (exact, in integers) and its share of the box, computed
    // as cv::blur computes it on the 0/1 floats (count · (1 / area) in double, then float).
    const int side = 2 * r + 1, area = side * side;
    cv::boxFilter(front_, front_count_, CV_16U, cv::Size(side, side), cv::Point(-1, -1), false,
                  cv::BORDER_REPLICATE);
    box_share_.resize(static_cast<std::size_t>(area) + 1);
    for (int k = 0; k <= area; ++k)
      box_share_[static_cast<std::size_t>(k)] = static_cast<float>(k * (1.0 / area));
  }
  // a = matte · blur(in_front); out = a · real + (1 − a) · virtual.
  compose_rows(v.colour, in.real_bgr, roi,
               [&](int y, float* a) {
                 const std::uint16_t* count = front_count_.ptr<std::uint16_t>(y - roi.y);
                 const float* matte = in.real_alpha.ptr<float>(y) + roi.x;
                 for (int x = 0; x < roi.width; ++x) a[x] = box_share_[count[x]] * matte[x];
               },
               *out, *alpha);
  return Ok{};
}

}  // namespace spidar::render
