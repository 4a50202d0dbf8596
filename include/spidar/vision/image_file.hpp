#pragma once
/// Reading an image file whose size is checked from its header before it is decoded.
///
/// OpenCV decodes an image of up to 2^30 pixels (its OPENCV_IO_MAX_IMAGE_PIXELS, read once when
/// the library loads, so a program cannot lower it for itself): a damaged or foreign file that
/// declares 30000x30000 px takes gigabytes and tens of seconds before it can be refused. These
/// functions read the declared size of a PNG, JPEG, BMP, PNM or TIFF file from its first bytes and refuse a
/// file beyond a bound without decoding it. Other formats are decoded under OpenCV's own bound.
#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"

namespace spidar::vision {

/// The largest image read_image decodes by default [px]: 64 Mpx, more than any camera's frame or
/// calibration picture.
inline constexpr std::int64_t kMaxDecodedPixels = std::int64_t{1} << 26;

/// Width and height [px] an image file declares in its header.
struct ImageFileSize {
  std::int64_t width = 0;
  std::int64_t height = 0;
  const char* format = "";  ///< "PNG", "JPEG", "BMP", "PNM" or "TIFF"
};

/// The size a PNG (IHDR), JPEG (the first start-of-frame segment), BMP (info header), PNM
/// (P1..P6) or TIFF (first directory) file declares; nullopt for another format or a header too
/// short or damaged to tell.
std::optional<ImageFileSize> image_file_size(const std::string& path);

/// True when `s` declares 1 to `max_pixels` pixels (no product of two 32-bit sides overflows).
bool declares_at_most(const ImageFileSize& s, std::int64_t max_pixels);

/// Ok when the file's header declares 1 to `max_pixels` pixels, or is of a format not read here
/// (OpenCV's own bound applies); Error naming the file when it declares more, or when it starts
/// as PNG, JPEG, BMP, PNM or TIFF but its header cannot be read.
Status check_image_header(const std::string& path, std::int64_t max_pixels = kMaxDecodedPixels);

/// cv::imread(path, flags) after the header's size is checked: Error naming the file when it
/// declares more than `max_pixels` (or a zero size), or when nothing decodes.
Result<cv::Mat> read_image(const std::string& path, int flags, std::int64_t max_pixels = kMaxDecodedPixels);

}  // namespace spidar::vision
