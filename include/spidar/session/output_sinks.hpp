#pragma once
/// Sinks that write a run's pictures: the composite into a video, and keyframes (montages of the
/// camera image, the fit and the composite at chosen times) as PNGs.
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "spidar/render/video_output.hpp"
#include "spidar/session/frame_sink.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::session {

/// Every frame's composite into `video` (closed at the end). Throws SpidarError if a write fails.
class VideoSink final : public FrameSink {
 public:
  /// Writes into a video opened by the caller.
  explicit VideoSink(render::VideoOutput& video) : video_(&video) {}
  /// Opens `path` (render::VideoOutput::open) in on_start, on the thread that runs the sink: the
  /// encoder's own threads then share that thread's priority (e.g. AsyncSinks' nice output
  /// thread). on_start throws SpidarError if it cannot be opened.
  VideoSink(std::string path, int width, int height, double fps)
      : path_(std::move(path)), width_(width), height_(height), fps_(fps) {}
  void on_start() override;
  void on_frame(const FrameEvent& e) override;
  void on_end(const SessionSummary& s) override;
  /// The video written to (null before on_start when the sink opens it).
  const render::VideoOutput* video() const { return video_; }

 private:
  render::VideoOutput* video_ = nullptr;
  std::unique_ptr<render::VideoOutput> own_;
  std::string path_;
  int width_ = 0, height_ = 0;
  double fps_ = 0;
};

/// At each of `times` [s] (ascending), the first frame at or after it: a keyframe montage
/// (sim::keyframe_montage) captioned by `caption`, composed then (the frame's buffers are reused)
/// and written as `dir`/keyframe_<n>_t<t>s.png after the run (a PNG takes tens of milliseconds,
/// which during the run would drop camera frames). Throws SpidarError if a write fails.
class KeyframeSink final : public FrameSink {
 public:
  /// The fitted hands are drawn with the models each frame was fitted with (FrameResult::models).
  KeyframeSink(std::string dir, std::vector<double> times, render::CompositeMode mode,
               const vision::Camera& camera, std::function<std::string(const FrameEvent&)> caption)
      : dir_(std::move(dir)), times_(std::move(times)), mode_(mode), camera_(camera),
        caption_(std::move(caption)) {}
  void on_frame(const FrameEvent& e) override;
  void on_end(const SessionSummary& s) override;
  /// The keyframes composed so far (path, montage).
  const std::vector<std::pair<std::string, cv::Mat>>& keyframes() const { return keyframes_; }

 private:
  std::string dir_;
  std::vector<double> times_;
  render::CompositeMode mode_;
  vision::Camera camera_;
  std::function<std::string(const FrameEvent&)> caption_;
  std::size_t next_ = 0;
  std::vector<std::pair<std::string, cv::Mat>> keyframes_;
};

}  // namespace spidar::session
