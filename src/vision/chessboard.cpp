#include "spidar/vision/chessboard.hpp"
#include "spidar/vision/image_file.hpp"
#include "spidar/core/config.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "opencv_interop.hpp"

namespace spidar::vision {

std::vector<Vec3> ChessboardPattern::corners_B() const {
  std::vector<Vec3> out;
  out.reserve(static_cast<std::size_t>(cols * rows));
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) out.emplace_back(i * square, j * square, 0.0);
  return out;
}

Result<ChessboardPattern> parse_pattern(const std::string& text, double square) {
  const auto x = text.find_first_of("xX");
  ChessboardPattern p;
  p.square = square;
  auto parse = [](std::string_view s, int* v) {
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), *v);
    return ec == std::errc() && ptr == s.data() + s.size();
  };
  const std::string_view t(text);
  if (x == std::string::npos || !parse(t.substr(0, x), &p.cols) ||
      !parse(t.substr(x + 1), &p.rows)) {
    return Error{"pattern '" + text + "': expected COLSxROWS inner corners, e.g. 9x6"};
  }
  if (p.cols < 3 || p.rows < 3 || p.cols > 100 || p.rows > 100) {
    return Error{"pattern '" + text + "': expected 3..100 inner corners per side"};
  }
  if (p.cols == p.rows) {
    return Error{"pattern '" + text +
                 "': expected different corner counts per side (a square board's orientation is "
                 "ambiguous)"};
  }
  // At least 0.1 mm: a printed board's square; smaller sides make OpenCV's calibration assert.
  if (!std::isfinite(square) || square < 1e-4 || square > 1.0) {
    return Error{"square " + core::number_for_message(square) + ": expected a side from 0.0001 to 1 m"};
  }
  return p;
}

std::optional<std::vector<Vec2>> find_chessboard_corners(const cv::Mat& image,
                                                         const ChessboardPattern& pattern) {
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    grey = image;
  }
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  std::vector<cv::Point2f> corners;
  const cv::Size size(pattern.cols, pattern.rows);
  const bool found = cv::findChessboardCorners(
      grey, size, corners,
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK);
  if (!found) return std::nullopt;
  cv::cornerSubPix(grey, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  std::vector<Vec2> out(corners.size());
  for (std::size_t i = 0; i < corners.size(); ++i) out[i] = {corners[i].x, corners[i].y};
  return out;
}

Result<IntrinsicsCalibration> calibrate_intrinsics(
    const std::vector<std::vector<Vec2>>& corners_per_view, const ChessboardPattern& pattern,
    int width, int height, const IntrinsicsOptions& options) {
  if (corners_per_view.size() < 3) {
    return Error{"calibrate: expected at least 3 views of the chessboard, got " +
                 std::to_string(corners_per_view.size())};
  }
  const auto board = pattern.corners_B();
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  for (std::size_t v = 0; v < corners_per_view.size(); ++v) {
    const auto& c = corners_per_view[v];
    if (c.size() != board.size()) {
      return Error{"calibrate: view " + std::to_string(v) + ": expected " +
                   std::to_string(board.size()) + " corners, got " + std::to_string(c.size())};
    }
    std::vector<cv::Point3f> o(board.size());
    std::vector<cv::Point2f> i(board.size());
    for (std::size_t k = 0; k < board.size(); ++k) {
      o[k] = {static_cast<float>(board[k].x()), static_cast<float>(board[k].y()), 0.f};
      i[k] = {static_cast<float>(c[k].x()), static_cast<float>(c[k].y())};
    }
    obj.push_back(std::move(o));
    img.push_back(std::move(i));
  }
  int flags = 0;
  if (options.fix_k3) flags |= cv::CALIB_FIX_K3;
  if (options.zero_tangential) flags |= cv::CALIB_ZERO_TANGENT_DIST;
  if (options.no_distortion) {
    flags |= cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2 | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST;
  }
  cv::Mat K, dist;
  std::vector<cv::Mat> rvecs, tvecs;
  cv::Mat std_in, std_ex, view_err;
  IntrinsicsCalibration out;
  try {
    out.rms_px = cv::calibrateCamera(obj, img, cv::Size(width, height), K, dist, rvecs, tvecs,
                                     std_in, std_ex, view_err, flags);
  } catch (const cv::Exception& e) {
    return Error{std::string("calibrate: OpenCV failed: ") + e.what()};
  }
  K.convertTo(K, CV_64F);
  out.intrinsics.fx = K.at<double>(0, 0);
  out.intrinsics.fy = K.at<double>(1, 1);
  out.intrinsics.cx = K.at<double>(0, 2);
  out.intrinsics.cy = K.at<double>(1, 2);
  out.intrinsics.distortion = detail::distortion_from_cv(dist);
  out.intrinsics.width = width;
  out.intrinsics.height = height;
  if (auto s = validate_intrinsics(out.intrinsics); !s.ok()) {
    return Error{"calibrate: implausible result (" + s.error().message +
                 "); use more views at varied angles"};
  }
  for (std::size_t v = 0; v < rvecs.size(); ++v) {
    out.X_CB.push_back(detail::pose_from_rvec_tvec(rvecs[v], tvecs[v]));
    out.view_rms_px.push_back(view_err.empty() ? 0.0 : view_err.at<double>(static_cast<int>(v)));
  }
  return out;
}

Result<std::vector<std::string>> list_images(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return Error{dir + ": no such folder"};
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    static const char* kExts[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm"};
    if (std::find(std::begin(kExts), std::end(kExts), ext) != std::end(kExts)) {
      out.push_back(e.path().string());
    }
  }
  if (ec) return Error{dir + ": cannot list folder: " + ec.message()};
  std::sort(out.begin(), out.end());
  return out;
}

Result<ChessboardFolderResult> calibrate_chessboard_folder(const std::string& dir,
                                                           const ChessboardPattern& pattern,
                                                           const IntrinsicsOptions& options) {
  auto files = list_images(dir);
  if (!files) return files.error();
  if (files->empty()) return Error{dir + ": no images (.png, .jpg, .bmp, .tif, .pgm, .ppm)"};
  ChessboardFolderResult out;
  std::vector<std::vector<Vec2>> corners;
  cv::Size size;
  for (const auto& f : *files) {
    auto read = read_image(f, cv::IMREAD_GRAYSCALE);
    if (!read) return read.error();
    const cv::Mat img = std::move(read).value();
    if (size.area() == 0) {
      size = img.size();
    } else if (img.size() != size) {
      return Error{f + ": image is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                   ", expected " + std::to_string(size.width) + "x" +
                   std::to_string(size.height) + " like the first image"};
    }
    if (auto c = find_chessboard_corners(img, pattern)) {
      corners.push_back(std::move(*c));
      out.used.push_back(f);
    } else {
      out.rejected.push_back(f);
    }
  }
  if (corners.size() < 3) {
    return Error{dir + ": found the " + std::to_string(pattern.cols) + "x" +
                 std::to_string(pattern.rows) + " chessboard in " +
                 std::to_string(corners.size()) + " of " + std::to_string(files->size()) +
                 " images; expected at least 3 (is --pattern the count of inner corners?)"};
  }
  auto cal = calibrate_intrinsics(corners, pattern, size.width, size.height, options);
  if (!cal) return cal.error();
  out.calibration = std::move(cal).value();
  return out;
}

}  // namespace spidar::vision
