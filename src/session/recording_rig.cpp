#include "spidar/session/recording_rig.hpp"

#include <filesystem>
#include <optional>

#include <opencv2/imgcodecs.hpp>

#include "spidar/core/clock.hpp"

namespace spidar::session {

/// The recorded frames in processing order, each taken as soon as asked for (no thread, no
/// dropping: a replay fits every frame the live run fitted, warm-started from the same fit).
class RecordingRig::Source final : public FrameSource {
 public:
  Source(const Recording& rec, int width, int height) : rec_(rec), width_(width), height_(height) {
    if (rec.meta.store != FrameStore::kPng) {
      auto cap = vision::Capture::open(rec.video_path);
      if (!cap) throw SpidarError(rec.dir + ": " + cap.error().message);
      video_ = std::move(cap).value();
    }
  }
  Status start(std::int64_t /*t0_ns*/) override { return Ok{}; }
  bool take(CameraFrame* out) override {
    // A frame that does not decode is counted and skipped (the next one is fitted from the last
    // decoded frame's fit, as the live loop does after a dropped frame).
    while (next_ < rec_.frames.size()) {
      const std::size_t i = next_++;
      const FrameRow& f = rec_.frames[i];
      if (video_) {
        auto fr = video_->read();
        image_ = fr ? fr->image : cv::Mat();
      } else {
        image_ = cv::imread((std::filesystem::path(rec_.dir) / f.image).string(), cv::IMREAD_COLOR);
      }
      if (image_.empty() || image_.cols != width_ || image_.rows != height_) {
        ++decode_errors_;
        continue;
      }
      row_ = i;
      ++delivered_;
      out->bgr = image_;
      out->t_exposure_ns = f.t_exposure_ns;
      out->filmed = nullptr;
      out->filmed_hold.reset();
      out->measured = &f.measured;
      out->scene_poses = i < rec_.scene.size() ? &rec_.scene[i] : nullptr;
      out->t_recorded_s = core::ns_to_s(f.t_exposure_ns - rec_.frames.front().t_exposure_ns);
      return true;
    }
    return false;
  }
  bool ended() const override { return next_ >= rec_.frames.size(); }
  std::string error() const override { return ""; }
  std::uint64_t delivered() const override { return delivered_; }
  void stop() override {}

  std::size_t row() const { return row_; }
  int decode_errors() const { return decode_errors_; }

 private:
  const Recording& rec_;
  int width_, height_;
  std::optional<vision::Capture> video_;
  cv::Mat image_;
  std::size_t next_ = 0, row_ = 0;
  std::uint64_t delivered_ = 0;
  int decode_errors_ = 0;
};

RecordingRig::RecordingRig(Recording recording, int width, int height)
    : recording_(std::move(recording)),
      source_(std::make_unique<Source>(recording_, width, height)) {}

RecordingRig::~RecordingRig() = default;

device::Device& RecordingRig::device() {
  throw SpidarError(name() + ": a recording has no device to drive");
}

FrameSource& RecordingRig::camera() { return *source_; }
std::size_t RecordingRig::row() const { return source_->row(); }
int RecordingRig::decode_errors() const { return source_->decode_errors(); }

}  // namespace spidar::session
