#pragma once
/// Ground-truth measures of one processed frame of the simulated rig: how well the fitted hands
/// cover the real ones (silhouette IoU), where their joints and fingertips are, and how often each
/// composite shows or hides the real hands where the truth would not.
#include <array>
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/sim/silhouette_loss.hpp"
#include "spidar/sim/synthetic_camera.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::sim {

struct FrameTruthMetrics {
  double iou = 0;                     ///< fitted hands' pixels vs the real hands' (no bracelet/arm)
  /// The real hands' pixels (palms and digits) in the image, and the fitted hands'. A frame with
  /// neither (the hands out of the camera's view) says nothing about the fit: its IoU (1 by
  /// convention for two empty masks) and joint error are left out of a run's figures
  /// (scored_in_image()).
  long real_hand_pixels = 0;
  long fitted_hand_pixels = 0;
  bool scored_in_image() const { return real_hand_pixels > 0 || fitted_hand_pixels > 0; }
  /// Where the fitted hands' pixels and the real hands' differ, per hand and part (iou's loss).
  SilhouetteLoss loss;
  std::array<double, 2> fingertip_mm{};  ///< mean fingertip cap error per hand [mm]
  std::array<double, 2> joint_px{};      ///< mean projected joint error per hand [px]
  /// The fitted wrist's depth (along the camera's optical axis) minus the true one per hand [mm]:
  /// the direction the image and the bracelet's midpoint observe least; it decides occlusion.
  std::array<double, 2> wrist_depth_mm{};
  /// The fitted wrist's distance from the true one in the image, per hand [px] (NaN when either
  /// is behind the camera): with wrist_depth_mm, where the wrist is wrong.
  std::array<double, 2> wrist_px{};
  /// How each fitted palm is turned against the true one [deg]: registration::palm_rotation_error_rad
  /// (x pitched, y rolled, z turned in the palm's plane, in the hand's own axes).
  std::array<Vec3, 2> palm_rotation_deg = zeros<Vec3, 2>();
  /// The paper's model's joint error floor per hand [px]: its skeleton with the user's true sizes
  /// at the true pose, with the little finger following the ring finger's (the paper's model has
  /// no parameters of their own for it; registration's little_free fits them, and can go below
  /// this); 0 for a user whose little finger follows the ring too.
  std::array<double, 2> joint_px_floor{};
  /// Hand region: the real hands (without forearm and bracelet) and wherever either composite
  /// shows the real image, except on the real forearm and bracelet.
  double occlusion_pct = 0;        ///< depth-mode composite vs the truth [% of the hand region]
  double occlusion_pct_paper = 0;  ///< paper-mode composite vs the truth [%]
  /// Contested pixels: the real hand (palm and digits) over a virtual object in the image, where
  /// depth order decides (render::contested_mask). Counts, so a run pools them over frames.
  long contested_pixels = 0;
  long contested_wrong = 0;        ///< of them, where the depth composite shows the wrong one
  long contested_wrong_paper = 0;  ///< … and the paper's composite
  double contested_pct() const {
    return contested_pixels > 0 ? 100.0 * static_cast<double>(contested_wrong) / static_cast<double>(contested_pixels) : 0.0;
  }
  double contested_pct_paper() const {
    return contested_pixels > 0 ? 100.0 * static_cast<double>(contested_wrong_paper) / static_cast<double>(contested_pixels) : 0.0;
  }
};

/// Reusable buffers.
struct FrameTruthWorkspace {
  cv::Mat model_mask, truth_alpha, region, tmp, contested;
};

/// Measures `result` (which must hold both composites: FramePipelineParams::other_composite)
/// against the frame's ground truth. `models`: the registration's hands; `truth_models` and
/// `truth`: the user's. Error if a composite is missing.
Result<FrameTruthMetrics> measure_frame(const SyntheticFrame& frame,
                                        const pipeline::FrameResult& result,
                                        render::CompositeMode main_mode,
                                        const std::array<hand::HandModel, 2>& models,
                                        const std::array<hand::HandModel, 2>& truth_models,
                                        const std::array<hand::HandParams, 2>& truth,
                                        const vision::Camera& camera, FrameTruthWorkspace* ws);

/// A keyframe for the report: the camera frame | the matte with the fitted hands' wireframe
/// and bracelet wrists, the depth composite | the paper composite, each labelled, with `caption`
/// (2×2). With the real hands' ids (`real_hand_id`, SyntheticFrame::hand_id; the simulated
/// camera's ground truth) a third column: the drawn fit against the real hands
/// (silhouette_loss_image, the IoU's pixels: what the fit misses and where it spills, palm and
/// digits apart) over a legend with the frame's counts per hand (3×2).
cv::Mat keyframe_montage(const cv::Mat& camera_bgr, const pipeline::FrameResult& result,
                         render::CompositeMode main_mode,
                         const std::array<hand::HandModel, 2>& models,
                         const vision::Camera& camera, const std::string& caption,
                         const cv::Mat* real_hand_id = nullptr);

}  // namespace spidar::sim
