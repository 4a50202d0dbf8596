#include "spidar/render/video_output.hpp"

#include <filesystem>
#include <string_view>
#include <vector>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "spidar/core/atomic_write.hpp"

namespace spidar::render {

Status write_png(const std::string& path, const cv::Mat& image) {
  if (image.empty()) return Error{"write_png: empty image for " + path};
  std::error_code ec;
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec) return Error{"write_png: cannot create folder " + parent.string() + ": " + ec.message()};
  std::vector<unsigned char> png;
  try {
    if (!cv::imencode(".png", image, png)) return Error{"write_png: cannot encode " + path};
  } catch (const cv::Exception& e) {
    return Error{"write_png: " + path + ": " + e.what()};
  }
  // Whole or not at all (temporary file + rename, through symlinks); no fsync: a recording writes
  // one per frame, and the rename alone keeps a killed run from leaving half an image.
  try {
    core::write_file_atomic(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()),
                            core::AtomicWriteOptions{.sync = false});
  } catch (const core::FileError& e) {
    return Error{std::string("write_png: ") + e.what()};
  }
  return Ok{};
}

const char* video_format_name(VideoFormat format) {
  switch (format) {
    case VideoFormat::kMp4H264: return "mp4/h264";
    case VideoFormat::kMp4Mpeg4: return "mp4/mpeg4";
    case VideoFormat::kAviMjpg: return "avi/mjpg";
  }
  return "?";
}

Result<std::unique_ptr<VideoOutput>> VideoOutput::open(const std::string& path, int width,
                                                       int height, double fps,
                                                       const VideoFormat* only) {
  if (width <= 0 || height <= 0 || !(fps > 0 && fps < 1000))
    return Error{"video: expected a positive size and 0 < fps < 1000, got " +
                 std::to_string(width) + "x" + std::to_string(height) + " at " +
                 std::to_string(fps)};
  struct Candidate {
    VideoFormat format;
    int api;
    int fourcc;
    const char* extension;
  };
  const Candidate candidates[] = {
      {VideoFormat::kMp4H264, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('a', 'v', 'c', '1'), ".mp4"},
      {VideoFormat::kMp4Mpeg4, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), ".mp4"},
      {VideoFormat::kAviMjpg, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
       ".avi"},
  };
  std::error_code ec;
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec) return Error{"video: cannot create the folder " + parent.string() + " for " + path + ": " + ec.message()};
  // A folder (or a device, a FIFO) where the video goes: say so, rather than falling back to
  // another format's file beside it (the fallbacks are for a missing encoder, not a blocked path).
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    return Error{"video: " + path + " exists and is not a file; expected a video file's path"};
  std::string tried;
  for (const Candidate& c : candidates) {
    if (only && *only != c.format) continue;
    const std::string file = std::filesystem::path(path).replace_extension(c.extension).string();
    auto writer = std::make_unique<cv::VideoWriter>();
    bool opened = false;
    try {
      opened = writer->open(file, c.api, c.fourcc, fps, cv::Size(width, height), true);
    } catch (const cv::Exception&) {
      opened = false;
    }
    if (opened) {
      std::unique_ptr<VideoOutput> out(new VideoOutput());
      out->writer_ = std::move(writer);
      out->format_ = c.format;
      out->path_ = file;
      out->size_ = cv::Size(width, height);
      return out;
    }
    std::filesystem::remove(file, ec);
    tried += (tried.empty() ? "" : ", ") + std::string(video_format_name(c.format));
  }
  return Error{"video: cannot open " + path + " for writing (tried " + tried + ")"};
}

VideoOutput::~VideoOutput() { close(); }

Status VideoOutput::write(const cv::Mat& bgr) {
  if (!writer_) return Error{"video: " + path_ + " is closed"};
  if (bgr.type() != CV_8UC3 || bgr.size() != size_)
    return Error{"video: frames for " + path_ + " must be CV_8UC3 " +
                 std::to_string(size_.width) + "x" + std::to_string(size_.height)};
  writer_->write(bgr);
  ++frames_;
  return Ok{};
}

void VideoOutput::close() {
  if (writer_) writer_->release();
  writer_.reset();
}

}  // namespace spidar::render
