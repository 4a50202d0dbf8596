#include "spidar/session/recording_rig.hpp"
#include "spidar/vision/image_file.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>

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
      std::string problem;
      if (video_) {
        auto fr = video_->read();
        image_ = fr ? fr->image : cv::Mat();
      } else {
        // The PNG's own size first: a damaged or foreign file declaring a huge image would
        // otherwise be decoded into gigabytes before its size could be refused.
        const std::string path = (std::filesystem::path(rec_.dir) / f.image).string();
        const auto size = vision::image_file_size(path);
        if (size && (size->width != width_ || size->height != height_)) {
          image_.release();
          problem = "a " + std::string(size->format) + " of " + std::to_string(size->width) + "x" +
                    std::to_string(size->height) + " px";
        } else if (auto read = vision::read_image(path, cv::IMREAD_COLOR)) {
          image_ = std::move(read).value();
        } else {
          image_.release();  // "no image decoded" below
        }
      }
      if (problem.empty() && image_.empty()) problem = "no image decoded";
      if (problem.empty() && (image_.cols != width_ || image_.rows != height_))
        problem = "an image of " + std::to_string(image_.cols) + "x" + std::to_string(image_.rows) + " px";
      if (!problem.empty()) {
        if (decode_errors_++ == 0)
          first_decode_error_ = "frame " + std::to_string(f.index) + (video_ ? "" : " (" + f.image + ")") + ": " +
                                problem + ", expected a " + std::to_string(width_) + "x" + std::to_string(height_) +
                                " px image";
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
  const std::string& first_decode_error() const { return first_decode_error_; }

 private:
  const Recording& rec_;
  int width_, height_;
  std::optional<vision::Capture> video_;
  cv::Mat image_;
  std::size_t next_ = 0, row_ = 0;
  std::uint64_t delivered_ = 0;
  int decode_errors_ = 0;
  std::string first_decode_error_;
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
const std::string& RecordingRig::first_decode_error() const { return source_->first_decode_error(); }

}  // namespace spidar::session
