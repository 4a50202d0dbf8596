#include "spidar/render/compositor.hpp"

#include <algorithm>
#include <cfloat>
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

  // Virtual-hand pixels, and for every pixel near them the nearest one.
  cv::compare(v.hand_depth, FLT_MAX, hand_mask_, cv::CMP_LT);
  vision::SilhouetteDistanceOptions dt_options;
  dt_options.max_distance_px = params_.max_carry_px;  // only pixels the carry can reach
  dt_options.downsample = 1;                           // exact labels at full resolution
  if (auto s = vision::silhouette_distance(hand_mask_, &distance_, dt_options); !s) return s;
  const float unmatched = params_.show_unmatched ? 1.f : 0.f;
  const auto margin = static_cast<float>(params_.depth_margin_m);
  const auto max_d = static_cast<float>(params_.max_carry_px);
  const cv::Rect& dt = distance_.roi;
  front_.create(roi.size(), CV_32FC1);
  for (int y = 0; y < roi.height; ++y) {
    const int iy = y + roi.y;
    const float* depth = v.depth.ptr<float>(iy);
    float* f = front_.ptr<float>(y);
    const bool row_in_dt = !distance_.empty && iy >= dt.y && iy < dt.y + dt.height;
    const int* lab = row_in_dt ? distance_.labels.ptr<int>(iy - dt.y) : nullptr;
    const float* dist = row_in_dt ? distance_.distance.ptr<float>(iy - dt.y) : nullptr;
    for (int x = 0; x < roi.width; ++x) {
      const int ix = x + roi.x;
      const int dx = ix - dt.x;
      if (!row_in_dt || dx < 0 || dx >= dt.width || dist[dx] > max_d) {
        f[x] = unmatched;
        continue;
      }
      const int l = lab[dx];
      const cv::Point q = l > 0 && l < static_cast<int>(distance_.label_pixel.size())
                              ? distance_.label_pixel[static_cast<std::size_t>(l)]
                              : cv::Point(-1, -1);
      if (q.x < 0) {
        f[x] = unmatched;
        continue;
      }
      const float carried = v.hand_depth.at<float>(q.y, q.x);
      f[x] = carried < depth[ix] + margin ? 1.f : 0.f;
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
