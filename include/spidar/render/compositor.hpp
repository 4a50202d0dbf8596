#pragma once
/// Merges the camera's real hands into a rendering of the virtual scene.
///
/// paper  As in the paper: the virtual hands are transparent. Wherever a virtual hand is
///        front-most (hand_depth < depth), the camera frame shows through; elsewhere the
///        rendering. A registration error shows as misplaced cut-outs.
/// depth  (default) The chroma-key matte decides where the real hand is; the virtual hands only
///        lend it depth. Every real-hand pixel takes the depth of the nearest virtual-hand pixel
///        (distance-transform labels, vision::silhouette_distance), so a model a few pixels off
///        the real hand neither cuts fingers off nor leaves holes. The real hand is shown where
///        that carried depth is in front of the scene (hand_depth < depth + depth_margin), with
///        the occlusion edge softened by a small box blur and multiplied by the matte's own soft
///        alpha:  out = a · real + (1 − a) · virtual,  a = matte · blur(in_front).
///        The nearest pixel is found on 2×2 blocks by default (carry_downsample).
///        Real-hand pixels farther than max_carry_px from any virtual-hand pixel (e.g. the
///        forearm, or no model at all) are shown or hidden by show_unmatched.
#include <opencv2/core/mat.hpp>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/vision/silhouette.hpp"

namespace spidar::render {

enum class CompositeMode { kPaper, kDepth };

/// "paper" / "depth" ↔ mode; parse error lists the choices.
Result<CompositeMode> parse_composite_mode(const std::string& name);
const char* composite_mode_name(CompositeMode mode);

struct CompositorParams {
  CompositeMode mode = CompositeMode::kDepth;
  double depth_margin_m = 0.0;  ///< the real hand wins ties within this margin [m]
  int edge_blur_px = 1;         ///< box-blur radius of the occlusion mask [px]; 0 = hard edge
  int max_carry_px = 48;        ///< how far a virtual hand's depth is carried [px], ≥ 1
  /// 1: the nearest virtual-hand pixel of every real-hand pixel (exact labels at full
  /// resolution); 2: the nearest 2×2 block holding one (the distance transform on a quarter of
  /// the pixels), whose nearest hand depth is carried: at most a pixel off, a third of the cost.
  int carry_downsample = 2;
  bool show_unmatched = true;   ///< real-hand pixels beyond max_carry_px: drawn on top or not
};

/// Error naming the bad field.
Status validate(const CompositorParams& params);

/// The inputs. `virt` needs colour, depth and hand_depth (Renderer::read with kColour | kDepth |
/// kHandDepth). `real_bgr`: the camera frame (paper) or the chroma key's despilled foreground
/// (depth). `real_alpha`: the chroma key's CV_32FC1 matte, 1 = hand (depth mode only).
struct CompositeInputs {
  const RenderTargets* virt = nullptr;
  cv::Mat real_bgr;
  cv::Mat real_alpha;
};

class Compositor {
 public:
  explicit Compositor(const CompositorParams& params = {}) : params_(params) {}
  const CompositorParams& params() const { return params_; }
  void set_params(const CompositorParams& params) { params_ = params; }

  /// Writes the composite (CV_8UC3) to `out`, reusing buffers between frames. Error on missing
  /// or mismatched inputs, naming which.
  Status compose(const CompositeInputs& in, cv::Mat* out);
  /// The alpha of the real image in the last composite (CV_32FC1, 0..1), for tests and debugging.
  const cv::Mat& last_alpha() const { return alpha_; }

 private:
  Status compose_paper(const CompositeInputs& in, cv::Mat* out);
  Status compose_depth(const CompositeInputs& in, cv::Mat* out);

  CompositorParams params_;
  cv::Mat hand_mask_, front_, alpha_;
  cv::Mat carried_;                ///< depth carried to each distance-map cell (NaN: none)
  std::vector<int> map_column_;    ///< roi column → distance-map column
  vision::SilhouetteDistance distance_;
};

}  // namespace spidar::render
