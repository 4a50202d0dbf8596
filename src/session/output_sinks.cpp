#include "spidar/session/output_sinks.hpp"

#include <cstdio>
#include <filesystem>

#include "spidar/sim/frame_truth.hpp"

namespace spidar::session {

void VideoSink::on_start() {
  if (video_ != nullptr) return;
  auto v = render::VideoOutput::open(path_, width_, height_, fps_);
  if (!v) throw SpidarError(v.error().message);
  own_ = std::move(v).value();
  video_ = own_.get();
}

void VideoSink::on_frame(const FrameEvent& e) {
  if (video_ == nullptr) throw SpidarError("video: " + path_ + " is not open (no on_start)");
  if (auto st = video_->write(e.result->composite); !st) throw SpidarError(st.error().message);
}

void VideoSink::on_end(const SessionSummary& /*s*/) {
  if (video_ != nullptr) video_->close();
}

void KeyframeSink::on_frame(const FrameEvent& e) {
  if (next_ >= times_.size() || e.t_s < times_[next_]) return;
  char name[64];
  std::snprintf(name, sizeof name, "keyframe_%d_t%04.1fs.png", static_cast<int>(next_) + 1, e.t_s);
  // With the simulated camera's ground truth, the fit against the real hands as well.
  const cv::Mat* real_hand_id = e.filmed != nullptr ? &e.filmed->wait_for_truth_images().hand_id : nullptr;
  keyframes_.emplace_back((std::filesystem::path(dir_) / name).string(),
                          sim::keyframe_montage(*e.bgr, *e.result, mode_, e.result->models, camera_, caption_(e),
                                                real_hand_id));
  ++next_;
}

void KeyframeSink::on_end(const SessionSummary& /*s*/) {
  for (const auto& [path, montage] : keyframes_) {
    if (auto st = render::write_png(path, montage); !st) throw SpidarError(st.error().message);
  }
}

}  // namespace spidar::session
