#include "spidar/vision/image_file.hpp"

#include <algorithm>
#include <array>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

namespace spidar::vision {
namespace {

std::uint32_t be16(const unsigned char* b) { return (std::uint32_t{b[0]} << 8) | b[1]; }
std::uint32_t be32(const unsigned char* b) { return (be16(b) << 16) | be16(b + 2); }
std::int32_t le32(const unsigned char* b) {
  return static_cast<std::int32_t>(std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) | (std::uint32_t{b[2]} << 16) |
                                   (std::uint32_t{b[3]} << 24));
}

/// JPEG: the segments after SOI (FF D8) until a start-of-frame (SOF0..SOF15 but DHT C4, JPG C8,
/// DAC CC), whose payload is precision (1 byte), height (2), width (2), big-endian.
std::optional<ImageFileSize> jpeg_size(std::ifstream& in) {
  in.seekg(2);
  for (int segment = 0; segment < 4096; ++segment) {
    unsigned char m[2];
    if (!in.read(reinterpret_cast<char*>(m), 2) || m[0] != 0xFF) return std::nullopt;
    while (m[1] == 0xFF)  // fill bytes
      if (!in.read(reinterpret_cast<char*>(m + 1), 1)) return std::nullopt;
    const unsigned marker = m[1];
    if (marker == 0xD8 || (marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) continue;  // no payload
    if (marker == 0xD9 || marker == 0xDA) return std::nullopt;  // end of image, or scan data before a frame
    unsigned char len[2];
    if (!in.read(reinterpret_cast<char*>(len), 2)) return std::nullopt;
    const std::uint32_t length = be16(len);
    if (length < 2) return std::nullopt;
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      unsigned char p[5];
      if (length < 7 || !in.read(reinterpret_cast<char*>(p), 5)) return std::nullopt;
      return ImageFileSize{be16(p + 3), be16(p + 1), "JPEG"};
    }
    in.seekg(length - 2, std::ios::cur);
  }
  return std::nullopt;
}

}  // namespace

std::optional<ImageFileSize> image_file_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 26> b{};
  if (!in.read(reinterpret_cast<char*>(b.data()), 2)) return std::nullopt;
  if (b[0] == 0xFF && b[1] == 0xD8) return jpeg_size(in);
  if (!in.read(reinterpret_cast<char*>(b.data() + 2), static_cast<std::streamsize>(b.size() - 2))) return std::nullopt;
  constexpr std::array<unsigned char, 8> kPng{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (std::equal(kPng.begin(), kPng.end(), b.begin())) {
    if (b[12] != 'I' || b[13] != 'H' || b[14] != 'D' || b[15] != 'R') return std::nullopt;
    return ImageFileSize{be32(&b[16]), be32(&b[20]), "PNG"};
  }
  if (b[0] == 'B' && b[1] == 'M') {
    // BITMAPINFOHEADER (or later): width, then height (negative: rows stored top-down).
    const std::int64_t w = le32(&b[18]), h = le32(&b[22]);
    return ImageFileSize{w < 0 ? -w : w, h < 0 ? -h : h, "BMP"};
  }
  return std::nullopt;
}

bool declares_at_most(const ImageFileSize& s, std::int64_t max_pixels) {
  return s.width > 0 && s.height > 0 && s.width <= max_pixels && s.height <= max_pixels &&
         s.width * s.height <= max_pixels;
}

Result<cv::Mat> read_image(const std::string& path, int flags, std::int64_t max_pixels) {
  if (const auto size = image_file_size(path)) {
    if (!declares_at_most(*size, max_pixels))
      return Error{path + ": the " + std::string(size->format) + " header declares " + std::to_string(size->width) +
                   "x" + std::to_string(size->height) + " px; expected 1 to " + std::to_string(max_pixels) +
                   " pixels (a damaged or foreign file?)"};
  }
  cv::Mat image;
  try {
    image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    return Error{path + ": cannot decode the image: " + e.what()};
  }
  if (image.empty()) return Error{path + ": cannot read the image (not an image, or damaged)"};
  return image;
}

}  // namespace spidar::vision
