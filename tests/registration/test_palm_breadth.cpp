// The palm's breadth in the image (palm_breadth.hpp): the model's chord against the pinhole
// formula, the measured chord against silhouettes of known breadth drawn with OpenCV, and the
// cases where a chord is no evidence.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "registration_test_util.hpp"
#include "spidar/hand/rotation_vector.hpp"
#include "spidar/registration/palm_breadth.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

using test::pinhole_camera;

/// The right model hand with its palm's level `at` at the world origin, its back facing the
/// camera turned by `tilt_rad` about its long axis, the fingers toward the image's right.
hand::HandParams facing_pose(const hand::HandModel& model, const vision::Camera& camera, double at,
                             double tilt_rad) {
  const Vec3 to_camera = camera.X_WC().p.normalized();  // from the origin
  Vec3 y = Vec3::UnitX() - Vec3::UnitX().dot(to_camera) * to_camera;
  y.normalize();
  const Vec3 z = Eigen::AngleAxisd(tilt_rad, y) * to_camera;
  Mat3 R;
  R.col(0) = y.cross(z);
  R.col(1) = y;
  R.col(2) = z;
  const hand::PalmBox& box = model.shape.palm;
  const Vec3 level_H(box.p_H_centre.x(), box.p_H_centre.y() - box.half_extents.y() + 2 * at * box.half_extents.y(),
                     box.p_H_centre.z());
  const Eigen::AngleAxisd aa(R);
  hand::HandParams q;
  q.set_wrist(-R * level_H, aa.angle() * aa.axis());
  return q;
}

/// A silhouette: a band `breadth_px` broad across direction `across` and 300 px long, centred on
/// `centre` (CV_8UC1, 255 inside).
cv::Mat band(const vision::Camera& camera, const Vec2& centre, const Vec2& across, double breadth_px) {
  cv::Mat mask = cv::Mat::zeros(camera.height(), camera.width(), CV_8UC1);
  const Vec2 along(-across.y(), across.x());
  std::vector<cv::Point2f> corners;
  for (const auto& [s, t] : {std::pair{-1, -1}, std::pair{1, -1}, std::pair{1, 1}, std::pair{-1, 1}}) {
    const Vec2 p = centre + 0.5 * s * breadth_px * across + 150.0 * t * along;
    corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  std::vector<cv::Point> pts;
  // Sub-pixel corners (4 fractional bits) so the band's breadth is not rounded to whole pixels.
  for (const auto& c : corners) pts.emplace_back(cvRound(c.x * 16), cvRound(c.y * 16));
  cv::fillConvexPoly(mask, pts, 255, cv::LINE_8, 4);
  return mask;
}

TEST(PalmBreadth, FaceOnTheModelsChordIsThePinholeBreadth) {
  const vision::Camera camera = pinhole_camera();
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const hand::HandParams q = facing_pose(model, camera, 0.85, 0.0);
  const double depth = camera.depth(Vec3::Zero());
  const Vec2 across = Vec2(0.0, 1.0);  // fingers along the image's x: across is its y
  const double expected = 2.0 * model.shape.palm.half_extents.x() * camera.intrinsics().fy / depth;
  // The section's extreme points lie in the palm's plane face on; off the optical axis the
  // perspective stretches them a little.
  EXPECT_NEAR(model_palm_chord_px(model, q, camera, 0.85, across), expected, 0.01 * expected);
  // Wider with the width, and the left hand's mirror image gives the same.
  const hand::HandModel wide = resized(model, 0.19, 0.095).value();
  EXPECT_NEAR(model_palm_chord_px(wide, facing_pose(wide, camera, 0.85, 0.0), camera, 0.85, across),
              expected * 0.095 / 0.085, 0.015 * expected);
}

TEST(PalmBreadth, MeasuresTheBreadthOfTheSilhouetteAcrossThePalm) {
  const vision::Camera camera = pinhole_camera();
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  for (const double tilt : {0.0, 0.4}) {
    const hand::HandParams q = facing_pose(model, camera, 0.85, tilt);
    const Vec2 centre = camera.project(Vec3::Zero());
    // The palm's long axis runs along the image's x here (world x, seen from the camera's front).
    const Vec2 across(0.0, 1.0);
    const double model_px = model_palm_chord_px(model, q, camera, 0.85, across);
    for (const double ratio : {0.9, 1.0, 1.12}) {
      const cv::Mat mask = band(camera, centre, across, ratio * model_px);
      const auto chord = measure_palm_chord(model, q, camera, mask, nullptr, 6);
      ASSERT_TRUE(chord.has_value()) << tilt << " " << ratio;
      EXPECT_NEAR(std::abs(chord->across_px.dot(across)), 1.0, 1e-3);
      EXPECT_NEAR(chord->measured_px, ratio * model_px, 1.5) << tilt << " " << ratio;
      EXPECT_DOUBLE_EQ(chord->at, 0.85);
    }
  }
}

TEST(PalmBreadth, NoChordWhereItIsNoEvidence) {
  const vision::Camera camera = pinhole_camera();
  const hand::HandModel model = hand::default_hand_model(hand::Side::kRight);
  const Vec2 centre = camera.project(Vec3::Zero());
  const Vec2 across(0.0, 1.0);
  const hand::HandParams q = facing_pose(model, camera, 0.85, 0.0);
  const double model_px = model_palm_chord_px(model, q, camera, 0.85, across);
  const cv::Mat good = band(camera, centre, across, model_px);
  ASSERT_TRUE(measure_palm_chord(model, q, camera, good, nullptr, 6).has_value());
  // Seen edge on.
  const hand::HandParams edge = facing_pose(model, camera, 0.85, 1.3);
  EXPECT_FALSE(measure_palm_chord(model, edge, camera, good, nullptr, 6).has_value());
  // The outline merges with something far broader (the other hand, a forearm).
  EXPECT_FALSE(measure_palm_chord(model, q, camera, band(camera, centre, across, 2.0 * model_px), nullptr, 6));
  // The palm's centre is not on the silhouette; no silhouette; the wrong type.
  EXPECT_FALSE(measure_palm_chord(model, q, camera, band(camera, centre + 3.0 * model_px * across, across, model_px),
                                  nullptr, 6));
  EXPECT_FALSE(measure_palm_chord(model, q, camera, cv::Mat(), nullptr, 6));
  cv::Mat as_float;
  good.convertTo(as_float, CV_32FC1);
  EXPECT_FALSE(measure_palm_chord(model, q, camera, as_float, nullptr, 6));
  // The line leaves the image: the palm at the image's border.
  cv::Mat cut = good.clone();
  const int row = static_cast<int>(std::lround(centre.y() + 0.25 * model_px));
  cut(cv::Rect(0, row, cut.cols, cut.rows - row)).setTo(255);
  EXPECT_FALSE(measure_palm_chord(model, q, camera, cut, nullptr, 6));
  // Pixels on the chord that this hand does not own (the other hand's, in front of it).
  std::vector<OwnedPixel> mine;
  for (int y = 3; y < good.rows; y += 6)
    for (int x = 3; x < good.cols; x += 6)
      if (good.at<std::uint8_t>(y, x) != 0) mine.push_back({Vec2(x, y), -1});
  EXPECT_TRUE(measure_palm_chord(model, q, camera, good, &mine, 6).has_value());
  std::vector<OwnedPixel> half;
  for (const OwnedPixel& o : mine)
    if (o.px.y() < centre.y()) half.push_back(o);
  EXPECT_FALSE(measure_palm_chord(model, q, camera, good, &half, 6).has_value());
  // A thumb lying beside the palm's edge on the line: the chord would be the palm and thumb.
  hand::HandParams thumb_in = q;
  thumb_in[hand::kThumbCmcAbduction] = 0.0;
  thumb_in[hand::kThumbCmcFlexion] = -0.6;
  cv::Mat with_thumb = good.clone();
  test::draw_capsule_mask(model, thumb_in, camera, &with_thumb);
  const auto thumbed = measure_palm_chord(model, thumb_in, camera, with_thumb, nullptr, 6);
  if (thumbed) {  // then the thumb is off the line: the chord is the palm's
    EXPECT_NEAR(thumbed->measured_px, model_palm_chord_px(model, thumb_in, camera, 0.85, thumbed->across_px), 0.1 * model_px);
  }
}

}  // namespace
}  // namespace spidar::registration
