#include "spidar/vision/image_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
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

/// PNM (P1..P6): whitespace-separated ASCII width and height after the magic, '#' comments.
std::optional<ImageFileSize> pnm_size(std::ifstream& in) {
  in.seekg(2);
  std::int64_t v[2] = {0, 0};
  for (std::int64_t& x : v) {
    int c = in.get();
    while (c == '#' || std::isspace(c)) {
      if (c == '#')
        while (c != '\n' && c != EOF) c = in.get();
      c = in.get();
    }
    if (!std::isdigit(c)) return std::nullopt;
    for (int digits = 0; std::isdigit(c); c = in.get())
      if (++digits > 10) return std::nullopt;
      else x = 10 * x + (c - '0');
  }
  return ImageFileSize{v[0], v[1], "PNM"};
}

/// TIFF: the first image file directory's ImageWidth (256) and ImageLength (257), SHORT or LONG.
std::optional<ImageFileSize> tiff_size(std::ifstream& in, bool little) {
  auto u16 = [little](const unsigned char* b) { return little ? std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) : be16(b); };
  auto u32 = [little, u16](const unsigned char* b) { return little ? u16(b) | (u16(b + 2) << 16) : be32(b); };
  unsigned char h[4];
  in.seekg(4);
  if (!in.read(reinterpret_cast<char*>(h), 4)) return std::nullopt;
  in.seekg(u32(h));
  unsigned char n[2];
  if (!in.read(reinterpret_cast<char*>(n), 2)) return std::nullopt;
  std::int64_t w = -1, ht = -1;
  for (std::uint32_t k = 0, count = u16(n); k < count && k < 4096; ++k) {
    unsigned char e[12];
    if (!in.read(reinterpret_cast<char*>(e), 12)) return std::nullopt;
    const std::uint32_t tag = u16(e), type = u16(e + 2);
    if (tag != 256 && tag != 257) continue;
    const std::int64_t value = type == 3 ? u16(e + 8) : type == 4 ? u32(e + 8) : -1;
    (tag == 256 ? w : ht) = value;
  }
  if (w < 0 || ht < 0) return std::nullopt;
  return ImageFileSize{w, ht, "TIFF"};
}

}  // namespace

namespace {

/// The declared size, as image_file_size; `*known` tells whether the first bytes are those of a
/// format read here (PNG, JPEG, BMP, PNM, TIFF), whether or not the rest of the header could be read.
std::optional<ImageFileSize> read_header(const std::string& path, bool* known) {
  *known = false;
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 26> b{};
  if (!in.read(reinterpret_cast<char*>(b.data()), 2)) return std::nullopt;
  *known = true;
  if (b[0] == 0xFF && b[1] == 0xD8) return jpeg_size(in);
  if (b[0] == 'P' && b[1] >= '1' && b[1] <= '6') return pnm_size(in);
  if ((b[0] == 'I' && b[1] == 'I') || (b[0] == 'M' && b[1] == 'M')) {
    unsigned char m[2];
    const bool little = b[0] == 'I';
    *known = in.read(reinterpret_cast<char*>(m), 2) &&
             ((little && m[0] == 42 && m[1] == 0) || (!little && m[0] == 0 && m[1] == 42));
    return *known ? tiff_size(in, little) : std::nullopt;
  }
  const bool png = b[0] == 0x89 && b[1] == 'P', bmp = b[0] == 'B' && b[1] == 'M';
  *known = png || bmp;
  if (!*known || !in.read(reinterpret_cast<char*>(b.data() + 2), static_cast<std::streamsize>(b.size() - 2)))
    return std::nullopt;
  constexpr std::array<unsigned char, 8> kPng{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (png) {
    if (!std::equal(kPng.begin(), kPng.end(), b.begin()) || b[12] != 'I' || b[13] != 'H' || b[14] != 'D' ||
        b[15] != 'R')
      return std::nullopt;
    return ImageFileSize{be32(&b[16]), be32(&b[20]), "PNG"};
  }
  // BMP, BITMAPINFOHEADER (or later): width, then height (negative: rows stored top-down).
  const std::int64_t w = le32(&b[18]), h = le32(&b[22]);
  return ImageFileSize{w < 0 ? -w : w, h < 0 ? -h : h, "BMP"};
}

}  // namespace

std::optional<ImageFileSize> image_file_size(const std::string& path) {
  bool known = false;
  return read_header(path, &known);
}

bool declares_at_most(const ImageFileSize& s, std::int64_t max_pixels) {
  return s.width > 0 && s.height > 0 && s.width <= max_pixels && s.height <= max_pixels &&
         s.width * s.height <= max_pixels;
}

Status check_image_header(const std::string& path, std::int64_t max_pixels) {
  bool known = false;
  if (const auto size = read_header(path, &known)) {
    if (!declares_at_most(*size, max_pixels))
      return Error{path + ": the " + std::string(size->format) + " header declares " + std::to_string(size->width) +
                   "x" + std::to_string(size->height) + " px; expected 1 to " + std::to_string(max_pixels) +
                   " pixels (a damaged or foreign file?)"};
    return Ok{};
  }
  // A file that starts as one of the formats read here but whose header cannot be read: refused
  // (a decoder that skips junk would still find a frame declaring any size).
  if (known) return Error{path + ": its image header cannot be read (damaged, or not what its first bytes say)"};
  return Ok{};
}

Result<cv::Mat> read_image(const std::string& path, int flags, std::int64_t max_pixels) {
  if (const Status st = check_image_header(path, max_pixels); !st) return st.error();
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
