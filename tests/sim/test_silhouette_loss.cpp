// The IoU's loss taken apart (sim/silhouette_loss.hpp): counts per hand and part on hand-drawn
// masks, against an independent IoU (registration::mask_iou) on random ones, and the errors.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "spidar/registration/metrics.hpp"
#include "spidar/hand/parameters.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"
#include "spidar/sim/silhouette_loss.hpp"

namespace spidar::sim {
namespace {

using render::encode_hand_id;

TEST(SilhouetteLoss, CountsMissedAndSpilledPixelsPerHandAndPart) {
  cv::Mat id(40, 60, CV_8UC1, cv::Scalar(0)), real(40, 60, CV_8UC1, cv::Scalar(0)),
      which(40, 60, CV_8UC1, cv::Scalar(0));
  // The real left hand: columns 0..19 of rows 0..9 (200 px); the real right: columns 30..49 (200).
  real(cv::Rect(0, 0, 20, 10)).setTo(255);
  which(cv::Rect(0, 0, 20, 10)).setTo(1);
  real(cv::Rect(30, 0, 20, 10)).setTo(255);
  which(cv::Rect(30, 0, 20, 10)).setTo(2);
  // The model's left palm covers columns 0..14 of rows 0..11: 150 on the hand, 30 spilled below.
  id(cv::Rect(0, 0, 15, 12)).setTo(encode_hand_id(0, render::kPalmPart));
  // Its right index finger covers columns 30..54 of row 0..3: 80 on the hand, 20 spilled right.
  id(cv::Rect(30, 0, 25, 4)).setTo(encode_hand_id(1, hand::kIndex));
  // The right forearm and bracelet are not the hand: they neither cover nor spill.
  id(cv::Rect(30, 4, 20, 2)).setTo(encode_hand_id(1, render::kForearmPart));
  id(cv::Rect(30, 6, 20, 1)).setTo(encode_hand_id(1, render::kBraceletPart));
  // A right palm drawn far from any real hand: 12 spilled.
  id(cv::Rect(0, 30, 4, 3)).setTo(encode_hand_id(1, render::kPalmPart));
  SilhouetteLoss l;
  ASSERT_TRUE(silhouette_loss(id, real, which, &l).ok());
  EXPECT_EQ(l.both, 150 + 80);
  EXPECT_EQ(l.missed[0], 200 - 150);
  EXPECT_EQ(l.missed[1], 200 - 80);
  EXPECT_EQ(l.spill_palm[0], 30);
  EXPECT_EQ(l.spill_digits[0], 0);
  EXPECT_EQ(l.spill_palm[1], 12);
  EXPECT_EQ(l.spill_digits[1], 20);
  EXPECT_DOUBLE_EQ(l.iou(), 230.0 / (230.0 + 50 + 120 + 30 + 12 + 20));

  SilhouetteLoss sum = l;
  sum += l;
  EXPECT_EQ(sum.both, 2 * l.both);
  EXPECT_EQ(sum.spill_digits[1], 40);
  EXPECT_DOUBLE_EQ(sum.iou(), l.iou());
  EXPECT_DOUBLE_EQ(SilhouetteLoss{}.iou(), 1.0);  // nothing drawn, nothing real: as mask_iou
}

TEST(SilhouetteLoss, ItsIouIsMaskIousOnRandomHands) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, 159), y(0, 119), r(3, 25), part(-1, 6), hand(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    cv::Mat id(120, 160, CV_8UC1, cv::Scalar(0)), real(120, 160, CV_8UC1, cv::Scalar(0)),
        which(120, 160, CV_8UC1, cv::Scalar(0));
    for (int k = 0; k < 6; ++k) {
      const int h = hand(rng);
      const cv::Point c(x(rng), y(rng));
      const int rad = r(rng);
      cv::circle(real, c, rad, cv::Scalar(255), cv::FILLED);
      cv::circle(which, c, rad, cv::Scalar(h + 1), cv::FILLED);
      cv::circle(id, cv::Point(x(rng), y(rng)), r(rng), cv::Scalar(encode_hand_id(hand(rng), part(rng))), cv::FILLED);
    }
    // The model's hand mask as the ground truth draws it: no forearm, no bracelet.
    cv::Mat model(id.size(), CV_8UC1);
    for (int i = 0; i < id.rows; ++i)
      for (int j = 0; j < id.cols; ++j) {
        const render::HandId d = render::decode_hand_id(id.at<std::uint8_t>(i, j));
        model.at<std::uint8_t>(i, j) =
            d.hand >= 0 && d.finger != render::kForearmPart && d.finger != render::kBraceletPart ? 255 : 0;
      }
    SilhouetteLoss l;
    ASSERT_TRUE(silhouette_loss(id, real, which, &l).ok());
    EXPECT_NEAR(l.iou(), registration::mask_iou(model, real), 1e-12) << "trial " << trial;
  }
}

TEST(SilhouetteLoss, RejectsImagesOfAnotherTypeOrSizeNamingThem) {
  const cv::Mat id(10, 10, CV_8UC1, cv::Scalar(0)), real(10, 10, CV_8UC1, cv::Scalar(0));
  SilhouetteLoss l;
  const auto small = silhouette_loss(id, real, cv::Mat(10, 9, CV_8UC1), &l);
  ASSERT_FALSE(small.ok());
  EXPECT_NE(small.error().message.find("real_hand_index is 9x10"), std::string::npos) << small.error().message;
  const auto wrong = silhouette_loss(id, cv::Mat(10, 10, CV_32FC1), real, &l);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("real_hand_only must be CV_8UC1"), std::string::npos) << wrong.error().message;
  EXPECT_FALSE(silhouette_loss(cv::Mat(), real, real, &l).ok());
}

}  // namespace
}  // namespace spidar::sim
