// vision::Capture on image sequences and video files written here, and its errors.
#include <gtest/gtest.h>

#include "temp_path.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <unistd.h>

#include "spidar/vision/capture.hpp"

namespace spidar::vision {
namespace {

namespace fs = std::filesystem;

using spidar::test::temp_dir;

cv::Mat numbered_frame(int k) {
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(200, 80, 30));
  cv::rectangle(img, cv::Rect(10 + 10 * k, 40, 30, 30), cv::Scalar(130, 160, 215), -1);
  return img;
}

TEST(Capture, ImageSequenceWithIndexTimestamps) {
  const std::string dir = temp_dir("spidar_vision_seq");
  for (int k = 1; k <= 5; ++k) {
    char name[64];
    std::snprintf(name, sizeof name, "/img_%04d.png", k);
    ASSERT_TRUE(cv::imwrite(dir + name, numbered_frame(k)));
  }
  CaptureOptions o;
  o.fallback_fps = 25.0;
  auto cap = Capture::open(dir + "/img_%04d.png", o);
  ASSERT_TRUE(cap.ok()) << cap.error().message;
  Capture c = std::move(cap).value();
  EXPECT_EQ(c.kind(), SourceKind::kImageSequence);
  for (int k = 0; k < 5; ++k) {
    auto f = c.read();
    ASSERT_TRUE(f.ok()) << f.error().message;
    EXPECT_EQ(f->index, k);
    EXPECT_DOUBLE_EQ(f->t_s, k / 25.0);
    EXPECT_EQ(f->image.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(f->image, numbered_frame(k + 1), cv::NORM_INF), 0.0);  // PNG is lossless
  }
  auto end = c.read();
  ASSERT_FALSE(end.ok());
  EXPECT_TRUE(c.at_end());
  EXPECT_NE(end.error().message.find("end of stream after 5 frames"), std::string::npos) << end.error().message;
  fs::remove_all(dir);
}

TEST(Capture, VideoFileUsesItsFrameRate) {
  const std::string dir = temp_dir("spidar_vision_video");
  const std::string file = dir + "/clip.avi";
  cv::VideoWriter w(file, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, cv::Size(160, 120));
  if (!w.isOpened()) GTEST_SKIP() << "no video writer backend for MJPG/AVI in this OpenCV build";
  for (int k = 0; k < 6; ++k) w.write(numbered_frame(k));
  w.release();
  auto cap = Capture::open(file);
  ASSERT_TRUE(cap.ok()) << cap.error().message;
  Capture c = std::move(cap).value();
  EXPECT_EQ(c.kind(), SourceKind::kVideoFile);
  EXPECT_DOUBLE_EQ(c.fps(), 20.0);
  int n = 0;
  while (true) {
    auto f = c.read();
    if (!f.ok()) break;
    EXPECT_DOUBLE_EQ(f->t_s, n / 20.0);
    EXPECT_EQ(f->image.cols, 160);
    ++n;
  }
  EXPECT_EQ(n, 6);
  EXPECT_TRUE(c.at_end());
  fs::remove_all(dir);
}

TEST(Capture, MissingSourcesAreNamedInErrors) {
  auto dev = Capture::open("/dev/video97");
  ASSERT_FALSE(dev.ok());
  EXPECT_NE(dev.error().message.find("camera device /dev/video97: no such device"), std::string::npos)
      << dev.error().message;
  auto idx = Capture::open_device(98);
  ASSERT_FALSE(idx.ok());
  EXPECT_NE(idx.error().message.find("/dev/video98"), std::string::npos) << idx.error().message;
  auto file = Capture::open("/nonexistent/clip.mp4");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.error().message, "video file /nonexistent/clip.mp4: no such file");
  auto seq = Capture::open("/nonexistent/img_%04d.png");
  ASSERT_FALSE(seq.ok());
  EXPECT_NE(seq.error().message.find("image sequence /nonexistent/img_%04d.png: no file matches"),
            std::string::npos);
  auto pattern = Capture::open("/tmp/img_%s.png");
  ASSERT_FALSE(pattern.ok());
  EXPECT_NE(pattern.error().message.find("%04d"), std::string::npos);
  // A file that is not a video.
  const std::string dir = temp_dir("spidar_vision_notvideo");
  { std::FILE* f = std::fopen((dir + "/notes.avi").c_str(), "w"); std::fputs("not a video", f); std::fclose(f); }
  auto junk = Capture::open(dir + "/notes.avi");
  ASSERT_FALSE(junk.ok());
  EXPECT_NE(junk.error().message.find("cannot decode"), std::string::npos) << junk.error().message;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace spidar::vision
