#include "spidar/render/compositor.hpp"

#include <algorithm>
#include <cfloat>
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

}  // namespace

Status Compositor::compose(const CompositeInputs& in, cv::Mat* out) {
  if (out == nullptr) return Error{"compositor: no output given"};
  if (auto s = validate(params_); !s) return s;
  return params_.mode == CompositeMode::kPaper ? compose_paper(in, out) : compose_depth(in, out);
}

Status Compositor::compose_paper(const CompositeInputs& in, cv::Mat* out) {
  if (auto s = check_inputs(in, false); !s) return s;
  const RenderTargets& v = *in.virt;
  cv::compare(v.hand_depth, v.depth, front_, cv::CMP_LT);  // virtual hand front-most
  v.colour.copyTo(*out);
  in.real_bgr.copyTo(*out, front_);
  front_.convertTo(alpha_, CV_32F, 1.0 / 255.0);
  return Ok{};
}

Status Compositor::compose_depth(const CompositeInputs& in, cv::Mat* out) {
  if (auto s = check_inputs(in, true); !s) return s;
  const RenderTargets& v = *in.virt;
  v.colour.copyTo(*out);
  alpha_.create(v.colour.size(), CV_32FC1);
  alpha_.setTo(0);
  // Only where the matte is non-zero can anything change.
  cv::compare(in.real_alpha, 0.f, hand_mask_, cv::CMP_GT);
  const int r = params_.edge_blur_px;
  cv::Rect roi = cv::boundingRect(hand_mask_);
  if (roi.area() == 0) return Ok{};
  const cv::Rect image(0, 0, v.colour.cols, v.colour.rows);
  roi = cv::Rect(roi.x - r, roi.y - r, roi.width + 2 * r, roi.height + 2 * r) & image;

  // Virtual-hand pixels, and for every pixel near them the nearest one (or the nearest 2×2 block
  // holding one: its blocks start at the distance transform's roi corner).
  cv::compare(v.hand_depth, FLT_MAX, hand_mask_, cv::CMP_LT);
  vision::SilhouetteDistanceOptions dt_options;
  dt_options.max_distance_px = params_.max_carry_px;  // only pixels the carry can reach
  dt_options.downsample = params_.carry_downsample;
  if (auto s = vision::silhouette_distance(hand_mask_, &distance_, dt_options); !s) return s;
  const float unmatched = params_.show_unmatched ? 1.f : 0.f;
  const auto margin = static_cast<float>(params_.depth_margin_m);
  const int sc = distance_.scale;
  const auto max_d = static_cast<float>(params_.max_carry_px) / static_cast<float>(sc);  // map units
  const cv::Rect& dt = distance_.roi;
  const int rows = v.hand_depth.rows, cols = v.hand_depth.cols;
  const float none = std::numeric_limits<float>::quiet_NaN();
  // Per map cell (a pixel, or a 2×2 block from the roi's corner): the depth carried there, the
  // front-most hand depth of the nearest cell holding a virtual-hand pixel; NaN: none in reach.
  carried_.create(distance_.empty ? cv::Size(1, 1) : distance_.labels.size(), CV_32FC1);
  carried_.setTo(none);
  for (int ly = 0; !distance_.empty && ly < carried_.rows; ++ly) {
    const int* lab = distance_.labels.ptr<int>(ly);
    const float* dist = distance_.distance.ptr<float>(ly);
    float* c = carried_.ptr<float>(ly);
    for (int lx = 0; lx < carried_.cols; ++lx) {
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
    map_column_[static_cast<std::size_t>(x)] = distance_.empty || lx >= carried_.cols ? -1 : lx;
  }
  front_.create(roi.size(), CV_32FC1);
  for (int y = 0; y < roi.height; ++y) {
    const int iy = y + roi.y;
    const float* depth = v.depth.ptr<float>(iy) + roi.x;
    float* f = front_.ptr<float>(y);
    const int ly = iy >= dt.y ? (iy - dt.y) / sc : -1;
    if (distance_.empty || ly < 0 || ly >= carried_.rows) {
      std::fill(f, f + roi.width, unmatched);
      continue;
    }
    const float* c = carried_.ptr<float>(ly);
    for (int x = 0; x < roi.width; ++x) {
      const int lx = map_column_[static_cast<std::size_t>(x)];
      const float carried = lx >= 0 ? c[lx] : none;
      f[x] = std::isnan(carried) ? unmatched : (carried < depth[x] + margin ? 1.f : 0.f);
    }
  }
  if (r > 0) cv::blur(front_, front_, cv::Size(2 * r + 1, 2 * r + 1), cv::Point(-1, -1),
                      cv::BORDER_REPLICATE);
  cv::Mat a = alpha_(roi);
  cv::multiply(front_, in.real_alpha(roi), a);
  // out = a · real + (1 − a) · virtual over the roi.
  for (int y = 0; y < roi.height; ++y) {
    const float* ap = a.ptr<float>(y);
    const std::uint8_t* rp = in.real_bgr.ptr<std::uint8_t>(y + roi.y) + 3 * roi.x;
    std::uint8_t* op = out->ptr<std::uint8_t>(y + roi.y) + 3 * roi.x;
    for (int x = 0; x < roi.width; ++x) {
      const float w = ap[x];
      if (w <= 0.f) continue;
      for (int c = 0; c < 3; ++c) {
        const float value = w * rp[3 * x + c] + (1.f - w) * op[3 * x + c];
        op[3 * x + c] = static_cast<std::uint8_t>(std::clamp(value + 0.5f, 0.f, 255.f));
      }
    }
  }
  return Ok{};
}

}  // namespace spidar::render
