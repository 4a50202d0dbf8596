#pragma once
/// Where a drawn hand model's silhouette and the real hands' differ, per hand and per part: the
/// IoU's loss taken apart, so that a run says which part of the gap to the ceiling is the palm's
/// and which the digits', and which hand's (docs/measurements.md, 2026-11-28: with the true sizes
/// the fitted palms' spill is the largest part of the fit's loss above the ceiling's).
#include <array>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/matx.hpp>

#include "spidar/core/result.hpp"

namespace spidar::sim {

/// Whether a hand id (render::encode_hand_id) is a hand's palm or digit: not empty, not its
/// forearm or bracelet (which the real hands' hand_only leaves out too).
bool is_hand_pixel(std::uint8_t hand_id);

/// Pixel counts of one frame [px]. With n_both the pixels both masks hold,
/// IoU = n_both / (n_both + Σ missed_palm + Σ missed_digits + Σ spill_palm + Σ spill_digits).
struct SilhouetteLoss {
  std::array<long, 2> missed_palm{};    ///< real hand h's palm that no model hand covers
  std::array<long, 2> missed_digits{};  ///< real hand h's digits (and nails) no model hand covers
  std::array<long, 2> spill_palm{};    ///< model hand h's palm off the real hands
  std::array<long, 2> spill_digits{};  ///< model hand h's digits off the real hands
  long both = 0;                       ///< real and model hand alike (either hand)
  /// The frame's IoU from these counts (1 when neither mask holds a pixel, as mask_iou).
  double iou() const;
  long real_pixels() const;   ///< the real hands' palms and digits
  long model_pixels() const;  ///< the model hands' palms and digits
  SilhouetteLoss& operator+=(const SilhouetteLoss& o);
};

/// Counts the loss of a model drawn into `model_hand_id` (CV_8UC1, render::RenderTargets::hand_id)
/// against the real hands filmed into `real_hand_id` (CV_8UC1, SyntheticFrame::hand_id). On both,
/// only palms and digits are the hand (is_hand_pixel). Error naming the image if a type or size
/// differs.
Status silhouette_loss(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, SilhouetteLoss* out);

/// Colours of silhouette_loss_image (BGR).
struct SilhouetteLossColours {
  cv::Vec3b both{150, 150, 150};          ///< real and model hand alike
  cv::Vec3b missed_palm{40, 40, 190};     ///< a real palm no model hand covers
  cv::Vec3b missed_digits{60, 150, 255};  ///< real digits no model hand covers
  cv::Vec3b spill_palm{190, 70, 20};      ///< a model palm off the real hands
  cv::Vec3b spill_digits{240, 220, 60};   ///< model digits off the real hands
};

/// The same comparison as a picture (CV_8UC3, the images' size; black where neither holds a hand
/// pixel): where the fit leaves the real hands uncovered and where it spills, by part, so that a
/// keyframe shows which part of the fit is off. Counting its colours gives silhouette_loss's
/// counts (both hands together). Same errors as silhouette_loss.
Status silhouette_loss_image(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, cv::Mat* bgr,
                             const SilhouetteLossColours& colours = {});

}  // namespace spidar::sim
