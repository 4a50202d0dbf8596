#pragma once
/// What a replay of a recording measures (`spidar-mr replay DIR`, docs/recording.md): without
/// ground truth, what a live session can measure — IoU of the fitted hands against the chroma-key
/// silhouette, the registration's residual terms and iterations — and how closely the replay
/// reproduces the recorded fits; and its report (report.json and plots).
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "spidar/session/frame_sink.hpp"
#include "spidar/session/recording_rig.hpp"

namespace spidar::session {

/// Per replayed frame: the fit's figures, and its comparison with the recorded fit of the same
/// frames.csv row (and of the recorded sample with one re-interpolated from fingertips.csv).
class ReplayScorer final : public FrameSink {
 public:
  explicit ReplayScorer(const RecordingRig& rig);
  void on_frame(const FrameEvent& e) override;

  struct Figures {
    std::vector<double> t, iou, iterations, ms;  ///< per frame: [s], IoU, both hands, [ms]
    std::array<std::vector<double>, 5> terms;    ///< fingertip, wrist, joint-ball, silhouette, prior
    double max_dq = 0, sum_dq = 0, max_dcost = 0, max_resample_mm = 0;
    int compared = 0, compared_hands = 0, broken_fits = 0, resampled = 0;
    /// The hand models' sizes, replay against live (fits.csv length_m, width_m), where recorded:
    /// the largest difference [mm] and how many hand fits were compared.
    double max_dsize_mm = 0;
    int compared_sizes = 0;
    /// Each hand's length and width [m] after the last frame: the replay's and the recording's
    /// (0 when not recorded).
    std::array<std::array<double, 2>, 2> final_size{}, live_final_size{};
  };
  const Figures& figures() const { return f_; }

 private:
  const RecordingRig& rig_;
  std::vector<device::FingertipSample> newest_first_;  ///< fingertips.csv, newest first
  cv::Mat scratch_;
  Figures f_;
};

/// Writes `out`/report.json and the plots (iou.png, residuals.png, iterations.png) of a replay
/// of `rig`'s recording; `video` is the replay's video path ("" if none). Returns the report.
/// Throws SpidarError if a file cannot be written.
nlohmann::json write_replay_report(const std::string& out, const RecordingRig& rig,
                                   const ReplayScorer& scorer, const std::string& video);

}  // namespace spidar::session
