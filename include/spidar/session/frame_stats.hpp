#pragma once
/// What a live session can measure per frame without ground truth, and the view model the GUI
/// and the headless summary read: the newest frame (camera image, fit, fingertip sample), a
/// bounded history for the plots, and running means over the whole run.
#include <array>
#include <cstdint>

#include <opencv2/core.hpp>

#include "spidar/device/servo_types.hpp"
#include "spidar/pipeline/frame_pipeline.hpp"
#include "spidar/registration/successive_adjustment.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/session/history_ring.hpp"

namespace spidar::session {

/// Numbers of one processed frame (no ground truth: these are what a live session can measure).
struct FrameStats {
  double t_s = 0;             ///< exposure time since the session started [s]
  double iou = 0;             ///< fitted hands' pixels vs the chroma-key silhouette
  std::array<registration::TermCosts, 2> terms{};  ///< final registration cost per term, per hand
  std::array<int, 2> iterations{};
  double latency_ms = 0;      ///< exposure to composite
  double pipeline_ms = 0;
  double registration_ms = 0;
  double servo_rate_hz = 0;   ///< since the previous frame
  double servo_jitter_max_us = 0;
};

/// IoU of the fitted hands (hand-id target, forearm included) against the chroma-key silhouette.
double silhouette_iou(const pipeline::FrameResult& r, cv::Mat* scratch);

/// The frame side's view model (the GUI reads it between steps, on the frame thread).
class FrameStatsSink final : public FrameSink {
 public:
  /// `capacity`: frames kept for the plots.
  explicit FrameStatsSink(std::size_t capacity = 1000) : history_(capacity) {}
  void on_frame(const FrameEvent& e) override;

  const HistoryRing<FrameStats>& history() const { return history_; }
  /// The newest frame (valid once a frame was processed).
  const cv::Mat& camera_image() const { return camera_image_; }
  const pipeline::FrameResult* result() const { return result_; }
  const device::FingertipSample& measured() const { return measured_; }
  /// Means over every frame of the run (0 before the first).
  double iou_mean() const { return mean(iou_sum_); }
  double registration_ms_mean() const { return mean(registration_ms_sum_); }

 private:
  double mean(double sum) const {
    return history_.pushed() == 0 ? 0.0 : sum / static_cast<double>(history_.pushed());
  }
  HistoryRing<FrameStats> history_;
  cv::Mat camera_image_, iou_scratch_;
  const pipeline::FrameResult* result_ = nullptr;
  device::FingertipSample measured_;
  double iou_sum_ = 0, registration_ms_sum_ = 0;
};

}  // namespace spidar::session
