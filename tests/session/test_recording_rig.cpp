// RecordingRig: a recording played back as a rig gives every recorded frame in order with the
// fingertip sample and scene poses it was processed with, skips (and counts) frames that do not
// decode or have another size, and has no device.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "recording_test_support.hpp"
#include "spidar/session/recording_rig.hpp"

namespace spidar::session::testing {
namespace {

TEST(RecordingRig, GivesEveryDecodableFrameInOrderWithItsRecordedInputs) {
  TempFolder d("recording_rig");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  // Real images for frames 0, 1 and 3, each a different grey; frame 2 does not decode, frame 4
  // has half the size.
  for (int i : {0, 1, 3})
    ASSERT_TRUE(cv::imwrite((dir / t.frames[static_cast<std::size_t>(i)].image).string(),
                            cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(40.0 * i + 10))));
  ASSERT_TRUE(cv::imwrite((dir / t.frames[4].image).string(), cv::Mat(24, 32, CV_8UC3, cv::Scalar::all(7))));

  RecordingRig rig(read_recording(dir.string()), 64, 48);
  EXPECT_TRUE(rig.plays_back());
  EXPECT_THROW(rig.device(), SpidarError);
  FrameSource& cam = rig.camera();
  ASSERT_TRUE(cam.start(0));
  std::vector<std::size_t> rows;
  CameraFrame f;
  while (cam.take(&f)) {
    const std::size_t i = rig.row();
    rows.push_back(i);
    EXPECT_EQ(f.bgr.at<cv::Vec3b>(5, 5)[0], static_cast<unsigned char>(40 * i + 10)) << i;
    EXPECT_EQ(f.t_exposure_ns, t.frames[i].t_exposure_ns);
    EXPECT_DOUBLE_EQ(f.t_recorded_s, 0.375 * static_cast<double>(i));
    ASSERT_NE(f.measured, nullptr);
    EXPECT_EQ(f.measured->p_W[1][2], t.frames[i].measured.p_W[1][2]);
    ASSERT_NE(f.scene_poses, nullptr);
    ASSERT_EQ(f.scene_poses->size(), 2u);
    EXPECT_EQ((*f.scene_poses)[1].p, t.scene[i][1].p);
    EXPECT_EQ(f.filmed, nullptr);
  }
  EXPECT_EQ(rows, (std::vector<std::size_t>{0, 1, 3}));
  EXPECT_TRUE(cam.ended());
  EXPECT_EQ(cam.delivered(), 3u);
  EXPECT_EQ(rig.decode_errors(), 2);
  EXPECT_EQ(rig.first_decode_error(), "frame 2 (" + t.frames[2].image + "): no image decoded, expected a 64x48 px image");
}

// A PNG that declares another size is refused from its header, before it is decoded (a damaged
// file declaring 30000 x 30000 px would take gigabytes): the header alone is enough to name it.
TEST(RecordingRig, APngOfAnotherSizeIsRefusedFromItsHeader) {
  TempFolder d("recording_rig_header");
  const fs::path dir = d.path() / "rec";
  const TestRecording t = make_test_recording(FrameStore::kPng);
  write_test_recording(t, dir);
  for (std::size_t i = 0; i < t.frames.size(); ++i)
    ASSERT_TRUE(cv::imwrite((dir / t.frames[i].image).string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(9))));
  // Frame 1: a PNG signature and an IHDR chunk declaring 30000 x 30000 px, and nothing more.
  const unsigned char header[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                  0, 0, 0x75, 0x30, 0, 0, 0x75, 0x30, 8, 2, 0, 0, 0};
  spit(dir / t.frames[1].image, std::string(reinterpret_cast<const char*>(header), sizeof header));
  RecordingRig rig(read_recording(dir.string()), 64, 48);
  CameraFrame f;
  std::vector<std::size_t> rows;
  while (rig.camera().take(&f)) rows.push_back(rig.row());
  EXPECT_EQ(rows.size(), t.frames.size() - 1);
  EXPECT_EQ(rig.decode_errors(), 1);
  EXPECT_EQ(rig.first_decode_error(),
            "frame 1 (" + t.frames[1].image + "): a PNG of 30000x30000 px, expected a 64x48 px image");
}

}  // namespace
}  // namespace spidar::session::testing
