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
///        Only the real hand's bounding box (grown by the blur radius) is composed; the rest of
///        the image is the rendering with a = 0.
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

  /// Writes the composite (CV_8UC3) to `out` and, if `alpha` is given, the share of the real
  /// image in it (CV_32FC1, 0..1) to `alpha`, reusing their buffers between frames (each pixel
  /// of both is written: no copy of the rendering is needed first). Error on missing or
  /// mismatched inputs, naming which.
  Status compose(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha = nullptr);
  /// The alpha of the real image in the last composite (CV_32FC1, 0..1), for tests and debugging:
  /// the compositor's own buffer, or the caller's `alpha` when one was given (shared, not copied).
  const cv::Mat& last_alpha() const { return alpha_; }

 private:
  Status compose_paper(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha);
  Status compose_depth(const CompositeInputs& in, cv::Mat* out, cv::Mat* alpha);
  /// In depth mode: fills front_ (roi-sized, 1 where the carried hand depth is in front of the
  /// scene, show_unmatched where no hand depth reaches) from the distance map of the virtual
  /// hand pixels. `roi` in image pixels.
  Status carry_hand_depth(const RenderTargets& virt, const cv::Rect& roi);

  CompositorParams params_;
  cv::Mat hand_mask_;
  cv::Mat front_;                  ///< CV_8UC1 over the roi: 1 = real hand in front, 0 = behind
  cv::Mat front_count_;            ///< CV_16UC1 over the roi: front_ pixels in the blur's box
  std::vector<float> box_share_;   ///< count → blurred value, count / box area (as cv::blur)
  cv::Mat alpha_;                  ///< see last_alpha()
  bool alpha_shared_ = false;      ///< alpha_ is the caller's buffer (last compose had `alpha`)
  cv::Mat carried_;                ///< depth carried to each distance-map cell (NaN: none)
  std::vector<int> map_column_;    ///< roi column → distance-map column
  vision::SilhouetteDistance distance_;
};

}  // namespace spidar::render
