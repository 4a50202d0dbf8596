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
  cv::Mat model(40, 60, CV_8UC1, cv::Scalar(0)), real(40, 60, CV_8UC1, cv::Scalar(0));
  // The real left palm: columns 0..19 of rows 0..9 (200 px); its thumb below, rows 10..11 (40).
  real(cv::Rect(0, 0, 20, 10)).setTo(encode_hand_id(0, render::kPalmPart));
  real(cv::Rect(0, 10, 20, 2)).setTo(encode_hand_id(0, hand::kThumb));
  // The real right index finger: columns 30..49 of rows 0..9 (200); its bracelet below (not the hand).
  real(cv::Rect(30, 0, 20, 10)).setTo(encode_hand_id(1, hand::kIndex));
  real(cv::Rect(30, 10, 20, 3)).setTo(encode_hand_id(1, render::kBraceletPart));
  // The model's left palm covers columns 0..14 of rows 0..13: 150 on the real palm, 30 on the
  // thumb, 30 spilled below it.
  model(cv::Rect(0, 0, 15, 14)).setTo(encode_hand_id(0, render::kPalmPart));
  // Its right index finger covers columns 30..54 of rows 0..3: 80 on the hand, 20 spilled right.
  model(cv::Rect(30, 0, 25, 4)).setTo(encode_hand_id(1, hand::kIndex));
  // The model's right forearm and bracelet are not the hand: they neither cover nor spill (the
  // forearm over the real bracelet is no pixel of either).
  model(cv::Rect(30, 4, 20, 2)).setTo(encode_hand_id(1, render::kForearmPart));
  model(cv::Rect(30, 10, 20, 1)).setTo(encode_hand_id(1, render::kBraceletPart));
  // A right palm drawn far from any real hand: 12 spilled.
  model(cv::Rect(0, 30, 4, 3)).setTo(encode_hand_id(1, render::kPalmPart));
  SilhouetteLoss l;
  ASSERT_TRUE(silhouette_loss(model, real, &l).ok());
  EXPECT_EQ(l.both, 150 + 30 + 80);
  EXPECT_EQ(l.missed_palm[0], 200 - 150);
  EXPECT_EQ(l.missed_digits[0], 40 - 30);
  EXPECT_EQ(l.missed_palm[1], 0);
  EXPECT_EQ(l.missed_digits[1], 200 - 80);
  EXPECT_EQ(l.spill_palm[0], 30);
  EXPECT_EQ(l.spill_digits[0], 0);
  EXPECT_EQ(l.spill_palm[1], 12);
  EXPECT_EQ(l.spill_digits[1], 20);
  EXPECT_DOUBLE_EQ(l.iou(), 260.0 / (260.0 + 50 + 10 + 120 + 30 + 12 + 20));

  SilhouetteLoss sum = l;
  sum += l;
  EXPECT_EQ(sum.both, 2 * l.both);
  EXPECT_EQ(sum.missed_digits[1], 240);
  EXPECT_EQ(sum.spill_digits[1], 40);
  EXPECT_DOUBLE_EQ(sum.iou(), l.iou());
  EXPECT_DOUBLE_EQ(SilhouetteLoss{}.iou(), 1.0);  // nothing drawn, nothing real: as mask_iou
}

/// The hand's own pixels (palm and digits) of a hand-id image, as the ground truth's masks hold them.
cv::Mat hand_mask(const cv::Mat& id) {
  cv::Mat m(id.size(), CV_8UC1);
  for (int i = 0; i < id.rows; ++i)
    for (int j = 0; j < id.cols; ++j) {
      const render::HandId d = render::decode_hand_id(id.at<std::uint8_t>(i, j));
      m.at<std::uint8_t>(i, j) =
          d.hand >= 0 && d.finger != render::kForearmPart && d.finger != render::kBraceletPart ? 255 : 0;
    }
  return m;
}

TEST(SilhouetteLoss, ItsIouIsMaskIousOnRandomHands) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, 159), y(0, 119), r(3, 25), part(-1, 6), hand(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    cv::Mat model(120, 160, CV_8UC1, cv::Scalar(0)), real(120, 160, CV_8UC1, cv::Scalar(0));
    for (int k = 0; k < 6; ++k) {
      for (cv::Mat* m : {&real, &model})
        cv::circle(*m, cv::Point(x(rng), y(rng)), r(rng), cv::Scalar(encode_hand_id(hand(rng), part(rng))), cv::FILLED);
    }
    SilhouetteLoss l;
    ASSERT_TRUE(silhouette_loss(model, real, &l).ok());
    EXPECT_NEAR(l.iou(), registration::mask_iou(hand_mask(model), hand_mask(real)), 1e-12) << "trial " << trial;
    long missed = 0;
    for (int h = 0; h < 2; ++h) missed += l.missed_palm[h] + l.missed_digits[h];
    cv::Mat uncovered;
    cv::bitwise_and(hand_mask(real), ~hand_mask(model), uncovered);
    EXPECT_EQ(missed, cv::countNonZero(uncovered)) << "trial " << trial;
    EXPECT_EQ(l.real_pixels(), cv::countNonZero(hand_mask(real))) << "trial " << trial;
    EXPECT_EQ(l.model_pixels(), cv::countNonZero(hand_mask(model))) << "trial " << trial;
  }
}

/// Pixels of `bgr` of colour `c`.
long count_colour(const cv::Mat& bgr, const cv::Vec3b& c) {
  long n = 0;
  for (int i = 0; i < bgr.rows; ++i)
    for (int j = 0; j < bgr.cols; ++j) n += bgr.at<cv::Vec3b>(i, j) == c ? 1 : 0;
  return n;
}

// The picture of the loss (for the keyframes): each class in its colour, so its colours' counts are
// the loss's (both hands together), on the hand-drawn pair above and on random hands; the rest black.
TEST(SilhouetteLoss, ItsPictureShowsEachPixelsClassInItsColour) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> x(0, 159), y(0, 119), r(3, 25), part(-1, 6), hand(0, 1);
  const SilhouetteLossColours c;
  for (int trial = 0; trial < 10; ++trial) {
    cv::Mat model(120, 160, CV_8UC1, cv::Scalar(0)), real(120, 160, CV_8UC1, cv::Scalar(0));
    for (int k = 0; k < 6; ++k)
      for (cv::Mat* m : {&real, &model})
        cv::circle(*m, cv::Point(x(rng), y(rng)), r(rng), cv::Scalar(encode_hand_id(hand(rng), part(rng))), cv::FILLED);
    SilhouetteLoss l;
    cv::Mat picture;
    ASSERT_TRUE(silhouette_loss(model, real, &l).ok());
    ASSERT_TRUE(silhouette_loss_image(model, real, &picture).ok());
    ASSERT_EQ(picture.type(), CV_8UC3);
    ASSERT_EQ(picture.size(), model.size());
    EXPECT_EQ(count_colour(picture, c.both), l.both) << "trial " << trial;
    EXPECT_EQ(count_colour(picture, c.missed_palm), l.missed_palm[0] + l.missed_palm[1]) << "trial " << trial;
    EXPECT_EQ(count_colour(picture, c.missed_digits), l.missed_digits[0] + l.missed_digits[1]) << "trial " << trial;
    EXPECT_EQ(count_colour(picture, c.spill_palm), l.spill_palm[0] + l.spill_palm[1]) << "trial " << trial;
    EXPECT_EQ(count_colour(picture, c.spill_digits), l.spill_digits[0] + l.spill_digits[1]) << "trial " << trial;
    cv::Mat either;
    cv::bitwise_or(hand_mask(model), hand_mask(real), either);
    EXPECT_EQ(count_colour(picture, cv::Vec3b(0, 0, 0)), picture.total() - cv::countNonZero(either)) << "trial " << trial;
  }
  const auto wrong = silhouette_loss_image(cv::Mat(10, 10, CV_8UC1), cv::Mat(9, 10, CV_8UC1), nullptr);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("silhouette_loss_image: real_hand_id is 10x9"), std::string::npos)
      << wrong.error().message;
}

TEST(SilhouetteLoss, RejectsImagesOfAnotherTypeOrSizeNamingThem) {
  const cv::Mat id(10, 10, CV_8UC1, cv::Scalar(0));
  SilhouetteLoss l;
  const auto small = silhouette_loss(id, cv::Mat(10, 9, CV_8UC1), &l);
  ASSERT_FALSE(small.ok());
  EXPECT_NE(small.error().message.find("real_hand_id is 9x10"), std::string::npos) << small.error().message;
  const auto wrong = silhouette_loss(cv::Mat(10, 10, CV_32FC1), id, &l);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("model_hand_id must be CV_8UC1"), std::string::npos) << wrong.error().message;
}

}  // namespace
}  // namespace spidar::sim
