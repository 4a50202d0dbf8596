#pragma once
/// Writing frames: PNG files, and video through OpenCV's VideoWriter.
///
/// Video formats are tried in order: MP4 with H.264 (FFmpeg backend, fourcc avc1; Debian's
/// FFmpeg encodes it with libx264), then MP4 with MPEG-4 Part 2 (mp4v, FFmpeg's own encoder), then
/// Motion-JPEG in AVI (MJPG, OpenCV's built-in writer, always present). The path's extension is
/// replaced to match (.mp4 / .avi); `format()` says which one was used.
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>

#include "spidar/core/result.hpp"

namespace cv {
class VideoWriter;
}

namespace spidar::render {

/// Writes an image as PNG, creating missing parent folders, whole or not at all
/// (core::write_file_atomic, without fsync). Error names the path.
Status write_png(const std::string& path, const cv::Mat& image);

enum class VideoFormat { kMp4H264, kMp4Mpeg4, kAviMjpg };
/// "mp4/h264", "mp4/mpeg4", "avi/mjpg".
const char* video_format_name(VideoFormat format);

class VideoOutput {
 public:
  /// Opens the first format that works (see above), or exactly `only` if given. Size in px,
  /// frames per second > 0. Error lists what was tried.
  static Result<std::unique_ptr<VideoOutput>> open(const std::string& path, int width, int height,
                                                   double fps, const VideoFormat* only = nullptr);
  ~VideoOutput();
  VideoOutput(const VideoOutput&) = delete;
  VideoOutput& operator=(const VideoOutput&) = delete;

  /// Appends a CV_8UC3 frame of the opened size.
  Status write(const cv::Mat& bgr);
  /// Finishes the file (also done by the destructor).
  void close();

  VideoFormat format() const { return format_; }
  const std::string& path() const { return path_; }
  int frames() const { return frames_; }

 private:
  VideoOutput() = default;
  std::unique_ptr<cv::VideoWriter> writer_;
  VideoFormat format_ = VideoFormat::kAviMjpg;
  std::string path_;
  cv::Size size_;
  int frames_ = 0;
};

}  // namespace spidar::render
