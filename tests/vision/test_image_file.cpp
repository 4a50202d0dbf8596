// Image files' declared sizes, read from their headers, against what OpenCV's encoders wrote; a
// header declaring a huge image is refused before anything is decoded.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "spidar/vision/capture.hpp"
#include "spidar/vision/image_file.hpp"
#include "temp_path.hpp"

namespace spidar::vision {
namespace {

std::string write_image(const std::string& dir, const std::string& name, int w, int h,
                        const std::vector<int>& params = {}) {
  cv::Mat m(h, w, CV_8UC3, cv::Scalar(30, 90, 200));
  cv::circle(m, {w / 2, h / 2}, std::min(w, h) / 3, cv::Scalar(250, 250, 250), cv::FILLED);
  if (name.size() > 4 && name.substr(name.size() - 4) == ".pgm") cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
  const std::string path = dir + "/" + name;
  EXPECT_TRUE(cv::imwrite(path, m, params)) << path;
  return path;
}

TEST(ImageFile, HeadersDeclareWhatTheEncodersWrote) {
  const std::string dir = test::temp_dir("spidar_image_file");
  struct Case {
    std::string name;
    int w, h;
    std::vector<int> params;
    const char* format;
  };
  const Case cases[] = {{"a.png", 640, 480, {}, "PNG"},
                        {"b.png", 17, 5, {}, "PNG"},
                        {"c.jpg", 641, 479, {}, "JPEG"},
                        {"d.jpg", 33, 1000, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}, "JPEG"},
                        {"e.bmp", 123, 45, {}, "BMP"},
                        {"f.pgm", 77, 31, {}, "PNM"},
                        {"g.ppm", 64, 48, {}, "PNM"},
                        {"h.tif", 99, 40, {}, "TIFF"}};
  for (const Case& c : cases) {
    const std::string path = write_image(dir, c.name, c.w, c.h, c.params);
    const auto size = image_file_size(path);
    ASSERT_TRUE(size.has_value()) << c.name;
    EXPECT_EQ(size->width, c.w) << c.name;
    EXPECT_EQ(size->height, c.h) << c.name;
    EXPECT_STREQ(size->format, c.format) << c.name;
    const auto read = read_image(path, cv::IMREAD_COLOR);
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read.value().cols, c.w);
    EXPECT_EQ(read.value().rows, c.h);
  }
  // A JPEG with a large APP segment (EXIF-like) before its frame header.
  {
    std::vector<unsigned char> jpg;
    cv::imencode(".jpg", cv::Mat(20, 30, CV_8UC3, cv::Scalar(1, 2, 3)), jpg);
    std::vector<unsigned char> app(2 + 2 + 60000, 0x41);
    app[0] = 0xFF, app[1] = 0xE1, app[2] = static_cast<unsigned char>((60002 >> 8) & 0xFF),
    app[3] = static_cast<unsigned char>(60002 & 0xFF);
    jpg.insert(jpg.begin() + 2, app.begin(), app.end());
    std::ofstream(dir + "/app.jpg", std::ios::binary).write(reinterpret_cast<const char*>(jpg.data()),
                                                            static_cast<std::streamsize>(jpg.size()));
    const auto size = image_file_size(dir + "/app.jpg");
    ASSERT_TRUE(size.has_value());
    EXPECT_EQ(size->width, 30);
    EXPECT_EQ(size->height, 20);
  }
  // Not an image, or too short to tell.
  std::ofstream(dir + "/text.png") << "hello";
  EXPECT_FALSE(image_file_size(dir + "/text.png").has_value());
  EXPECT_FALSE(image_file_size(dir + "/missing.png").has_value());
  const auto text = read_image(dir + "/text.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.error().message.find(dir + "/text.png: cannot read the image"), std::string::npos)
      << text.error().message;
}

TEST(ImageFile, AHeaderDeclaringAHugeImageIsRefusedWithoutDecoding) {
  const std::string dir = test::temp_dir("spidar_image_file_huge");
  // A real PNG whose IHDR is rewritten to 30000x30000 px (900 Mpx, under OpenCV's own 2^30 bound).
  std::vector<unsigned char> png;
  cv::imencode(".png", cv::Mat(8, 8, CV_8UC3, cv::Scalar(5, 6, 7)), png);
  for (int k : {16, 20}) {
    png[k] = 0, png[k + 1] = 0, png[k + 2] = 0x75, png[k + 3] = 0x30;  // 30000
  }
  const std::string path = dir + "/huge.png";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(png.data()),
                                              static_cast<std::streamsize>(png.size()));
  const auto size = image_file_size(path);
  ASSERT_TRUE(size.has_value());
  EXPECT_EQ(size->width, 30000);
  const auto read = read_image(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().message.find(path + ": the PNG header declares 30000x30000 px; expected 1 to 67108864 pixels"),
            std::string::npos)
      << read.error().message;
  // The same file as a later frame of an image sequence: refused when the sequence opens.
  write_image(dir, "seq_0003.png", 16, 12);
  write_image(dir, "seq_0004.png", 16, 12);
  std::filesystem::copy_file(path, dir + "/seq_0005.png");
  const auto cap = Capture::open(dir + "/seq_%04d.png");
  ASSERT_FALSE(cap.ok());
  EXPECT_NE(cap.error().message.find("seq_0005.png: the PNG header declares 30000x30000 px"), std::string::npos)
      << cap.error().message;
  // A pattern whose field would format names of a gigabyte.
  const auto wide = Capture::open(dir + "/seq_%999999999d.png");
  ASSERT_FALSE(wide.ok());
  EXPECT_NE(wide.error().message.find("expected exactly one integer field"), std::string::npos) << wide.error().message;
  // A JPEG whose frame header is hidden behind a stray byte (a decoder that skips junk finds it).
  std::vector<unsigned char> jpg;
  cv::imencode(".jpg", cv::Mat(8, 8, CV_8UC3, cv::Scalar(9, 9, 9)), jpg);
  jpg.insert(jpg.begin() + 2, 0x00);
  std::ofstream(dir + "/garbled.jpg", std::ios::binary).write(reinterpret_cast<const char*>(jpg.data()),
                                                              static_cast<std::streamsize>(jpg.size()));
  const auto garbled = read_image(dir + "/garbled.jpg", cv::IMREAD_COLOR);
  ASSERT_FALSE(garbled.ok());
  EXPECT_NE(garbled.error().message.find("garbled.jpg: its image header cannot be read"), std::string::npos)
      << garbled.error().message;
  // Sides whose product would overflow 64 bits, and a zero side.
  EXPECT_FALSE(declares_at_most({0xFFFFFFFFll, 0xFFFFFFFFll, "PNG"}, kMaxDecodedPixels));
  EXPECT_FALSE(declares_at_most({0, 10, "PNG"}, kMaxDecodedPixels));
  EXPECT_TRUE(declares_at_most({8192, 8192, "PNG"}, kMaxDecodedPixels));
  EXPECT_FALSE(declares_at_most({8192, 8193, "PNG"}, kMaxDecodedPixels));
}

}  // namespace
}  // namespace spidar::vision
