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
}

}  // namespace
}  // namespace spidar::session::testing
