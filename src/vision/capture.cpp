#include "spidar/vision/capture.hpp"
#include "spidar/vision/image_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>
#include <opencv2/videoio.hpp>

#include "spidar/core/clock.hpp"

namespace spidar::vision {
namespace {

namespace fs = std::filesystem;

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() < 6 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

/// The file name of index i in an image-sequence pattern (one %d field); empty if it cannot be formatted.
std::string sequence_name(const std::string& pattern, int i) {
  std::string name(pattern.size() + 32, '\0');
  const int n = std::snprintf(name.data(), name.size(), pattern.c_str(), i);
  if (n <= 0 || static_cast<std::size_t>(n) >= name.size()) return {};
  name.resize(static_cast<std::size_t>(n));
  return name;
}

/// The first index of an image-sequence pattern that names a file (OpenCV starts there).
std::optional<int> first_sequence_index(const std::string& pattern) {
  for (int i = 0; i <= 1000; ++i) {
    std::error_code ec;
    const std::string name = sequence_name(pattern, i);
    if (name.empty()) return std::nullopt;
    if (fs::is_regular_file(name, ec)) return i;
  }
  return std::nullopt;
}

/// Accepts exactly one printf integer conversion (%d, %04d, ... with a width of at most two
/// digits: %999999999d would format names of a gigabyte) and no other '%'.
bool valid_sequence_pattern(const std::string& p) {
  int conversions = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] != '%') continue;
    std::size_t j = i + 1;
    while (j < p.size() && std::isdigit(static_cast<unsigned char>(p[j]))) ++j;
    if (j - (i + 1) > 2) return false;
    if (j >= p.size() || p[j] != 'd') return false;
    ++conversions;
    i = j;
  }
  return conversions == 1;
}

}  // namespace

const char* to_string(SourceKind kind) {
  switch (kind) {
    case SourceKind::kDevice: return "device";
    case SourceKind::kVideoFile: return "video file";
    case SourceKind::kImageSequence: return "image sequence";
  }
  return "?";
}

Capture::Capture(std::unique_ptr<cv::VideoCapture> cap, SourceKind kind, std::string name,
                 double fps)
    : cap_(std::move(cap)), kind_(kind), name_(std::move(name)), fps_(fps) {}
Capture::Capture(Capture&&) noexcept = default;
Capture& Capture::operator=(Capture&&) noexcept = default;
Capture::~Capture() = default;

int Capture::width() const {
  return static_cast<int>(cap_->get(cv::CAP_PROP_FRAME_WIDTH));
}
int Capture::height() const {
  return static_cast<int>(cap_->get(cv::CAP_PROP_FRAME_HEIGHT));
}

Result<Capture> Capture::open_device(int index, const CaptureOptions& options) {
  return open(std::to_string(index), options);
}

Result<Capture> Capture::open(const std::string& source, const CaptureOptions& options) {
  if (!(options.fallback_fps > 0.0) || !std::isfinite(options.fallback_fps)) {
    return Error{"capture " + source + ": fallback_fps: expected a positive rate [Hz]"};
  }
  auto cap = std::make_unique<cv::VideoCapture>();
  std::error_code ec;
  try {
    if (all_digits(source) || source.rfind("/dev/", 0) == 0) {
      const std::string path = all_digits(source) ? "/dev/video" + std::to_string(std::stoi(source))
                                                  : source;
      if (!fs::exists(path, ec)) {
        return Error{"camera device " + source + ": no such device (" + path +
                     " does not exist; is the camera plugged in? see `ls /dev/video*`)"};
      }
      const bool opened = all_digits(source) ? cap->open(std::stoi(source), cv::CAP_V4L2)
                                             : cap->open(path, cv::CAP_V4L2);
      if (!opened || !cap->isOpened()) {
        return Error{"camera device " + source + ": cannot open " + path +
                     " with V4L2 (busy, no permission, or not a capture device)"};
      }
      if (options.width > 0) cap->set(cv::CAP_PROP_FRAME_WIDTH, options.width);
      if (options.height > 0) cap->set(cv::CAP_PROP_FRAME_HEIGHT, options.height);
      double fps = cap->get(cv::CAP_PROP_FPS);
      if (!(fps > 0.0) || !std::isfinite(fps)) fps = options.fallback_fps;
      return Capture(std::move(cap), SourceKind::kDevice, source, fps);
    }
    if (source.find('%') != std::string::npos) {
      if (!valid_sequence_pattern(source)) {
        return Error{"image sequence " + source +
                     ": expected exactly one integer field such as %04d in the pattern"};
      }
      const auto first = first_sequence_index(source);
      if (!first) {
        return Error{"image sequence " + source +
                     ": no file matches the pattern (tried indices 0..1000)"};
      }
      // Every file's declared size, from its header, as the sequence opens: a foreign or damaged
      // file declaring a huge image (or one whose header cannot be read) is refused before OpenCV
      // decodes it. (Files added to the sequence while it plays are not checked.)
      for (int i = *first;; ++i) {
        const std::string name = sequence_name(source, i);
        if (name.empty() || !fs::is_regular_file(name, ec)) break;
        if (const Status st = check_image_header(name); !st)
          return Error{"image sequence " + source + ": " + st.error().message};
      }
      if (!cap->open(source, cv::CAP_IMAGES) || !cap->isOpened()) {
        return Error{"image sequence " + source + ": OpenCV cannot read it"};
      }
      return Capture(std::move(cap), SourceKind::kImageSequence, source, options.fallback_fps);
    }
    if (!fs::exists(source, ec)) return Error{"video file " + source + ": no such file"};
    if (!fs::is_regular_file(source, ec)) return Error{"video file " + source + ": not a file"};
    // FFmpeg, then OpenCV's own MJPEG/AVI reader. Not CAP_ANY: probing every backend (GStreamer,
    // camera SDKs) on a file is slow, noisy, and leaks inside those libraries.
    bool opened = cap->open(source, cv::CAP_FFMPEG) && cap->isOpened();
    if (!opened) opened = cap->open(source, cv::CAP_OPENCV_MJPEG) && cap->isOpened();
    if (!opened) {
      return Error{"video file " + source +
                   ": cannot decode it (unsupported format or codec, or not a video)"};
    }
  } catch (const cv::Exception& e) {
    return Error{"capture " + source + ": OpenCV failed: " + e.what()};
  }
  double fps = cap->get(cv::CAP_PROP_FPS);
  if (!(fps > 0.0) || !std::isfinite(fps) || fps > 10000.0) fps = options.fallback_fps;
  return Capture(std::move(cap), SourceKind::kVideoFile, source, fps);
}

Result<Frame> Capture::read() {
  Frame f;
  bool ok = false;
  try {
    ok = cap_->read(f.image);
  } catch (const cv::Exception& e) {
    return Error{std::string(to_string(kind_)) + " " + name_ + ": frame " +
                 std::to_string(next_index_) + ": OpenCV failed: " + e.what()};
  }
  const std::int64_t t_ns = core::monotonic_ns();
  if (!ok || f.image.empty()) {
    at_end_ = kind_ != SourceKind::kDevice;
    return Error{std::string(to_string(kind_)) + " " + name_ +
                 (at_end_ ? ": end of stream after " : ": no frame (device stopped?) after ") +
                 std::to_string(next_index_) + " frames"};
  }
  if (f.image.channels() == 1) {
    cv::Mat bgr;
    cv::merge(std::vector<cv::Mat>{f.image, f.image, f.image}, bgr);
    f.image = bgr;
  }
  f.index = next_index_++;
  f.t_s = kind_ == SourceKind::kDevice ? core::ns_to_s(t_ns)
                                       : static_cast<double>(f.index) / fps_;
  return f;
}

}  // namespace spidar::vision
