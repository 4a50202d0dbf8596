#pragma once
/// Camera frames from OpenCV's VideoCapture: a V4L2 device (index "0" or path "/dev/video0"),
/// a video file, or an image sequence (printf pattern such as "frames/img_%04d.png").
///
/// Timestamps: a live device stamps each frame with the host's monotonic clock
/// (core::monotonic_ns, seconds) right after the frame is grabbed, so they compare directly
/// with the servo thread's fingertip samples. Files and image sequences have no host time:
/// frame k is stamped k / fps (the file's rate; image sequences and files without one use
/// CaptureOptions::fallback_fps), starting at 0.
#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>

#include "spidar/core/result.hpp"

namespace cv {
class VideoCapture;
}

namespace spidar::vision {

enum class SourceKind { kDevice, kVideoFile, kImageSequence };

const char* to_string(SourceKind kind);

struct CaptureOptions {
  double fallback_fps = 30.0;  ///< [Hz] for sources that do not report a frame rate
  int width = 0;               ///< requested size for devices [px]; 0 = the device's default
  int height = 0;
};

struct Frame {
  cv::Mat image;          ///< 8-bit BGR
  std::int64_t index = 0; ///< 0, 1, 2, ... in reading order
  double t_s = 0;         ///< timestamp [s] (see the header comment for its clock)
};

class Capture {
 public:
  /// Opens a source given as text: digits = device index, "/dev/..." = device path, a '%'
  /// pattern = image sequence, anything else = video file. Errors name the source and say
  /// what is missing (no such device, no such file, no file matching the pattern, cannot decode).
  static Result<Capture> open(const std::string& source, const CaptureOptions& options = {});
  static Result<Capture> open_device(int index, const CaptureOptions& options = {});

  Capture(Capture&&) noexcept;
  Capture& operator=(Capture&&) noexcept;
  ~Capture();

  SourceKind kind() const { return kind_; }
  const std::string& name() const { return name_; }  ///< the source as given
  double fps() const { return fps_; }                ///< [Hz] used for file timestamps
  int width() const;
  int height() const;

  /// The next frame. At the end of a file or sequence, or when a device stops delivering, an
  /// error naming the source and the frame count; at_end() then tells the two apart.
  Result<Frame> read();
  bool at_end() const { return at_end_; }

 private:
  Capture(std::unique_ptr<cv::VideoCapture> cap, SourceKind kind, std::string name, double fps);

  std::unique_ptr<cv::VideoCapture> cap_;
  SourceKind kind_ = SourceKind::kVideoFile;
  std::string name_;
  double fps_ = 30.0;
  std::int64_t next_index_ = 0;
  bool at_end_ = false;
};

}  // namespace spidar::vision
