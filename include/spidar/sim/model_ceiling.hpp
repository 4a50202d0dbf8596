#pragma once
/// The ceiling of the registration's hand model: the model's own skin, with the user's true
/// sizes, posed at the user's true pose, against the real hands' silhouette. No fit can cover
/// the real hands better than this (up to the pose freedom the model lacks, e.g. the little
/// finger's own posture), so it is reported beside every fitted IoU: what is below it is the
/// fit's; what is between it and 1 is the model's shape.
#include <array>
#include <memory>
#include <optional>
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"
#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/render/context.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/sim/silhouette_loss.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::sim {

class ModelCeiling {
 public:
  /// `user`: the user's hands (left, right) as the model's skeleton with their true sizes;
  /// `model_skin`: the registration's skin (FramePipelineParams::model_skin). The context must be
  /// current on the calling thread whenever iou() is called.
  static Result<std::unique_ptr<ModelCeiling>> create(render::Context& context,
                                                      const vision::Camera& camera,
                                                      const std::array<hand::HandModel, 2>& user,
                                                      const render::HandSkinParams& model_skin);
  ~ModelCeiling();
  /// IoU of the model skin at `truth` (left, right) against `real_hand_only` (CV_8UC1, the
  /// real palms and digits, no forearm or bracelet: SyntheticFrame::hand_only).
  /// `toward_elbow_W`: where the real forearms pointed (SyntheticFrame::toward_elbow_W); the
  /// model's forearms point there too (the elbow is part of the true pose).
  /// With `loss`, also where the skin and the real hands differ, per hand and part, which needs
  /// `real_hand_id` (SyntheticFrame::hand_id).
  Result<double> iou(const std::array<hand::HandParams, 2>& truth, const cv::Mat& real_hand_only,
                     const std::array<std::optional<Vec3>, 2>& toward_elbow_W,
                     const cv::Mat& real_hand_id = cv::Mat(), SilhouetteLoss* loss = nullptr);

 private:
  struct Impl;
  explicit ModelCeiling(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace spidar::sim
