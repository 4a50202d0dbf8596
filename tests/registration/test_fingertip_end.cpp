// The fingertips' reach beyond their caps read from the image (fingertip_end.hpp), against mattes
// ray-cast from a hand whose caps sit elsewhere than the model's (an independent rendering: each
// pixel's rays tested against the hand's skin capsules, ends rounded at the bone's end as the
// skin's are), and the size estimator taking the offset from it.
#include <gtest/gtest.h>

#include <cmath>

#include "registration_test_util.hpp"
#include "spidar/hand/hand_shape.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/registration/fingertip_end.hpp"
#include "spidar/registration/shape_estimator.hpp"

namespace spidar::registration {
namespace {

/// The rig camera at twice its resolution, without distortion (a pixel ≈ 0.4 mm at the hand).
vision::Camera fine_camera() { return test::pinhole_camera(2.0); }

/// The default right hand with its caps `reach_m` back from the fingertips along the distal bone.
hand::HandModel hand_with_reach(double reach_m) {
  hand::HandModel m = hand::default_hand_model(hand::Side::kRight);
  hand::HandDimensions d = m.shape.dimensions;
  d.fingertip_offset = Vec3(0.0, -reach_m, 0.0);
  m.shape = hand::make_hand_shape(d).value();
  return m;
}

/// The hand's back toward the camera, fingers straight toward the image's right, its middle
/// fingertip near the world origin; the fingers then pitched `pitch_rad` away from the camera
/// (about the hand's x axis).
hand::HandParams pose_facing(const vision::Camera& camera, double pitch_rad) {
  const Vec3 to_camera = camera.X_WC().p.normalized();
  Vec3 y = Vec3::UnitX() - Vec3::UnitX().dot(to_camera) * to_camera;
  y.normalize();
  Mat3 R;
  R.col(0) = y.cross(to_camera);
  R.col(1) = y;
  R.col(2) = to_camera;
  R = R * Eigen::AngleAxisd(pitch_rad, Vec3::UnitX()).toRotationMatrix();
  const Eigen::AngleAxisd aa(R);
  hand::HandParams q;
  q.set_wrist(-R * Vec3(0.0, 0.15, 0.0), aa.angle() * aa.axis());
  return q;
}

/// Distance from the ray o + t v (v unit, t ≥ 0) to segment a–b [m]: the closest points by
/// alternating projections from the lines' own closest pair (converged at these angles).
double ray_segment_distance(const Vec3& o, const Vec3& v, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double dd = d.dot(d);
  const double dv = d.dot(v);
  const double den = dd - dv * dv;
  double s = den > 1e-18 ? (d.dot(o - a) - dv * v.dot(o - a)) / den : 0.0;
  double t = 0.0;
  for (int i = 0; i < 4; ++i) {
    s = dd > 0 ? std::clamp(s, 0.0, 1.0) : 0.0;
    t = std::max(0.0, (a + s * d - o).dot(v));
    if (dd > 0) s = (o + t * v - a).dot(d) / dd;
  }
  s = dd > 0 ? std::clamp(s, 0.0, 1.0) : 0.0;
  t = std::max(0.0, (a + s * d - o).dot(v));
  return (o + t * v - (a + s * d)).norm();
}

/// The matte of `truth` at `q` (CV_32FC1): the share of 4×4 rays per pixel that hit one of its
/// skin's capsules (hand_render_shapes: the last phalanx ends at the bone's end), plus any extra
/// discs (centre [m], radius [m]) in `blobs`.
cv::Mat ray_cast_matte(const hand::HandModel& truth, const hand::HandParams& q, const vision::Camera& camera,
                       const std::vector<std::pair<Vec3, double>>& blobs = {}) {
  std::vector<hand::Capsule> caps = hand::hand_render_shapes(truth, q).capsules;
  for (const auto& [c, r] : blobs) caps.push_back({c, c, r, -1, -1});
  const Vec3 o = camera.X_WC().p;
  cv::Mat alpha(camera.height(), camera.width(), CV_32FC1, cv::Scalar(0));
  // Each capsule's box in the image (its ends' projections grown by its projected radius, and a
  // margin): a ray outside it cannot hit it.
  std::vector<cv::Rect2d> boxes;
  const double focal = camera.intrinsics().fx;
  for (const hand::Capsule& c : caps) {
    const Vec2 a = camera.project(c.p_W_a), b = camera.project(c.p_W_b);
    const double r = 1.5 * c.radius * focal / std::min(camera.depth(c.p_W_a), camera.depth(c.p_W_b)) + 2.0;
    boxes.emplace_back(std::min(a.x(), b.x()) - r, std::min(a.y(), b.y()) - r, std::abs(a.x() - b.x()) + 2 * r,
                       std::abs(a.y() - b.y()) + 2 * r);
  }
  auto hit = [&](double u, double v) {
    const Vec3 dir = camera.ray_direction_W(Vec2(u, v)).normalized();
    for (std::size_t i = 0; i < caps.size(); ++i)
      if (boxes[i].contains(cv::Point2d(u, v)) &&
          ray_segment_distance(o, dir, caps[i].p_W_a, caps[i].p_W_b) <= caps[i].radius)
        return true;
    return false;
  };
  // Whole pixels first, then 4×4 rays where a pixel's neighbours disagree.
  cv::Mat coarse(camera.height(), camera.width(), CV_8UC1);
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) coarse.at<std::uint8_t>(y, x) = hit(x, y) ? 1 : 0;
  for (int y = 0; y < camera.height(); ++y)
    for (int x = 0; x < camera.width(); ++x) {
      const int c0 = coarse.at<std::uint8_t>(y, x);
      bool edge = false;
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1 && !edge; ++dx) {
          const int yy = std::clamp(y + dy, 0, camera.height() - 1), xx = std::clamp(x + dx, 0, camera.width() - 1);
          edge = coarse.at<std::uint8_t>(yy, xx) != c0;
        }
      if (!edge) {
        alpha.at<float>(y, x) = static_cast<float>(c0);
        continue;
      }
      int n = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) n += hit(x - 0.375 + 0.25 * i, y - 0.375 + 0.25 * j) ? 1 : 0;
      alpha.at<float>(y, x) = static_cast<float>(n / 16.0);
    }
  return alpha;
}

/// What the strings measure: the caps of `truth` at `q`, exactly.
HandObservation strings_of(const hand::HandModel& truth, const hand::HandParams& q) {
  return test::exact_caps(truth, q);
}

TEST(FingertipEnd, ReadsTheFingertipsReachBeyondTheCapsNotTheModels) {
  const vision::Camera camera = fine_camera();
  const hand::HandModel model = hand_with_reach(0.008);  // the profile's
  for (const double truth_reach : {0.010, 0.0065}) {
    const hand::HandModel truth = hand_with_reach(truth_reach);
    const hand::HandParams q = pose_facing(camera, 0.0);
    const cv::Mat alpha = ray_cast_matte(truth, q, camera);
    ProjectedHand outline;
    project_hand(model, q, camera, 0.0, &outline);
    const std::vector<FingertipEnd> ends =
        fingertip_ends(model, q, strings_of(truth, q), camera, alpha, 0.5, {}, &outline);
    ASSERT_EQ(ends.size(), 3u) << "index, middle and ring seen side on; the thumb left out";
    for (const FingertipEnd& e : ends) {
      EXPECT_NE(e.finger, hand::kThumb);
      EXPECT_LT(e.tilt_rad, 0.2);
      EXPECT_NEAR(e.reach_m, truth_reach, 0.0003) << "finger " << e.finger;
    }
    // With the thumb asked for, it is measured too (here its tip is seen side on as well).
    FingertipEndParams with_thumb;
    with_thumb.thumb = true;
    const auto all = fingertip_ends(model, q, strings_of(truth, q), camera, alpha, 0.5, with_thumb, &outline);
    EXPECT_GE(all.size(), ends.size());
  }
}

TEST(FingertipEnd, TakesTheRoundedEndSeenTiltedOffTheReach) {
  // Pitched 25° out of the image plane, the rounded end shows ρ (1/cos φ − 1) ≈ 0.7 mm further
  // along the axis than its end; the measure takes it off.
  const vision::Camera camera = fine_camera();
  const hand::HandModel model = hand_with_reach(0.008);
  const hand::HandModel truth = hand_with_reach(0.010);
  for (const double pitch : {0.45, -0.45}) {
    const hand::HandParams q = pose_facing(camera, pitch);
    const cv::Mat alpha = ray_cast_matte(truth, q, camera);
    const auto ends = fingertip_ends(model, q, strings_of(truth, q), camera, alpha, 0.5);
    ASSERT_FALSE(ends.empty()) << "pitch " << pitch;
    for (const FingertipEnd& e : ends) {
      EXPECT_GT(e.tilt_rad, 0.3);
      EXPECT_NEAR(e.reach_m, 0.010, 0.0004) << "finger " << e.finger << ", pitch " << pitch;
    }
  }
  // Tilted beyond max_tilt_rad: no evidence.
  const hand::HandParams steep = pose_facing(camera, 0.9);
  const auto none = fingertip_ends(model, steep, strings_of(truth, steep), camera,
                                   ray_cast_matte(truth, steep, camera), 0.5);
  EXPECT_TRUE(none.empty());
}

TEST(FingertipEnd, GivesNoSampleWhereTheEndIsNotTheFingertips) {
  const vision::Camera camera = fine_camera();
  const hand::HandModel model = hand_with_reach(0.008);
  const hand::HandModel truth = hand_with_reach(0.010);
  const hand::HandParams q = pose_facing(camera, 0.0);
  const hand::HandPoints pts = hand::forward_kinematics(truth, q);
  const Vec3 index_tip = pts.p_W_joint[hand::joint_index(hand::kIndex, 3)];
  const Vec3 index_dir = (index_tip - pts.p_W_joint[hand::joint_index(hand::kIndex, 2)]).normalized();
  // Something beyond the index's tip that the matte merges it with (the other hand, say): the
  // walk runs on past any reach.
  const cv::Mat merged = ray_cast_matte(truth, q, camera, {{index_tip + 0.015 * index_dir, 0.02}});
  HandObservation obs = strings_of(truth, q);
  ProjectedHand outline;
  project_hand(model, q, camera, 0.0, &outline);
  for (const FingertipEnd& e : fingertip_ends(model, q, obs, camera, merged, 0.5, {}, &outline))
    EXPECT_NE(e.finger, hand::kIndex);
  // An unmeasured string, or a fit whose cap misses the string's by more than max_cap_miss_m.
  const cv::Mat alpha = ray_cast_matte(truth, q, camera);
  obs.fingertip_valid[hand::kMiddle] = false;
  obs.p_W_fingertip[hand::kRing] += Vec3(0.0, 0.0, 0.005);
  const auto ends = fingertip_ends(model, q, obs, camera, alpha, 0.5, {}, &outline);
  ASSERT_EQ(ends.size(), 1u);
  EXPECT_EQ(ends[0].finger, hand::kIndex);
  // Bad input: an empty matte, a matte of another type, a non-finite pose.
  EXPECT_TRUE(fingertip_ends(model, q, obs, camera, cv::Mat(), 0.5).empty());
  EXPECT_TRUE(fingertip_ends(model, q, obs, camera, cv::Mat(10, 10, CV_64FC1, cv::Scalar(1)), 0.5).empty());
  hand::HandParams bad = q;
  bad.q[0] = std::nan("");
  EXPECT_TRUE(fingertip_ends(model, bad, obs, camera, alpha, 0.5).empty());
}

TEST(FingertipEnd, TheSizeEstimatorTakesTheCapsOffsetFromTheImage) {
  const vision::Camera camera = fine_camera();
  const hand::HandModel model = hand_with_reach(0.008);
  const hand::HandModel truth = hand_with_reach(0.010);
  const hand::HandParams q = pose_facing(camera, 0.0);
  const cv::Mat alpha = ray_cast_matte(truth, q, camera);
  HandObservation obs = strings_of(truth, q);
  obs.wrist_px = camera.project(q.p_W_wrist());
  ImageEvidence image;
  image.camera = &camera;
  image.alpha = alpha;
  RegistrationParams fit;
  for (const bool on : {true, false}) {
    ShapeEstimatorParams p;
    p.min_pose_change = 0.0;   // the same frame offered again is a keyframe
    p.solve_every = 1000;      // no size re-estimate: the offset alone
    p.cap_offset_from_image = on;
    p.cap_offset_min_samples = 9;
    ShapeEstimator estimator(model, p);
    bool changed = false;
    for (int i = 0; i < 3; ++i) changed = estimator.add_frame(q, obs, image, fit) || changed;
    const ShapeEstimate e = estimator.estimate();
    if (on) {
      EXPECT_TRUE(changed);
      EXPECT_EQ(e.cap_reach_samples, 9);
      EXPECT_NEAR(e.cap_reach_m, 0.010, 0.0003);
      EXPECT_NEAR(-estimator.model().shape.dimensions.fingertip_offset.y(), 0.010, 0.0003);
      // The skeleton is the profile's: only the caps moved.
      EXPECT_DOUBLE_EQ(estimator.model().shape.dimensions.length, model.shape.dimensions.length);
    } else {
      EXPECT_FALSE(changed);
      EXPECT_EQ(e.cap_reach_samples, 0);
      EXPECT_DOUBLE_EQ(e.cap_reach_m, 0.008);
    }
  }
  // Never beyond cap_offset_max_change_m of the profile's.
  ShapeEstimatorParams p;
  p.min_pose_change = 0.0;
  p.solve_every = 1000;
  p.cap_offset_min_samples = 3;
  p.cap_offset_max_change_m = 0.001;
  ShapeEstimator bounded(model, p);
  (void)bounded.add_frame(q, obs, image, fit);
  EXPECT_EQ(bounded.estimate().cap_reach_samples, 0) << "10 mm lies beyond 8 ± 1 mm: not a reach it may take";
}

}  // namespace
}  // namespace spidar::registration
