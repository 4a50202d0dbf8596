// The silhouette term's coverage direction (coverage.hpp): the projected outline against
// independent references (OpenCV's convex hull and polygon test, a densely sampled capsule),
// which hand owns which pixel, and that uncovered pixels place a palm the strings leave free.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <cstdio>
#include <random>

#include "spidar/hand/kinematics.hpp"
#include "spidar/registration/metrics.hpp"

#include "registration_test_util.hpp"
#include "spidar/registration/coverage.hpp"

namespace spidar::registration {
namespace {

TEST(Coverage, CapsuleDistanceMatchesADenselySampledCapsule) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  for (int k = 0; k < 50; ++k) {
    ImageCapsule c;
    c.a = Vec2(u(rng), u(rng));
    c.c = Vec2(u(rng), u(rng));
    c.ra = 1.0 + 0.1 * u(rng);
    c.rc = k < 25 ? c.ra : 1.0 + 0.1 * u(rng);  // equal radii first, then a cone
    c.valid = true;
    const Vec2 p(u(rng), u(rng));
    // Brute force: the union of discs along the axis (the capsule with linearly varying radius
    // as this module draws it), 20001 samples.
    double brute = 1e9;
    for (int i = 0; i <= 20000; ++i) {
      const double t = i / 20000.0;
      brute = std::min(brute, (p - (c.a + t * (c.c - c.a))).norm() - (c.ra + t * (c.rc - c.ra)));
    }
    // Measured from the closest axis point, not the exact distance to a cone's flank: exact for
    // equal radii, otherwise never nearer than the truth and farther by at most |rc − ra|.
    const double d = capsule_distance(c, p);
    EXPECT_GE(d, brute - 1e-3) << k;
    EXPECT_LE(d, brute + std::abs(c.rc - c.ra) + 1e-3) << k;
    if (k < 25) {
      EXPECT_NEAR(d, brute, 1e-3) << k;
    }
  }
  ImageCapsule none;
  EXPECT_TRUE(std::isinf(capsule_distance(none, Vec2(1, 1))));
}

TEST(Coverage, PalmHullAgreesWithOpenCv) {
  const auto models = test::model_hands();
  const auto poses = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  std::mt19937 rng(7);
  int inside = 0, outside = 0;
  for (int h = 0; h < 2; ++h) {
    for (int variant = 0; variant < 4; ++variant) {
      const hand::HandParams q = test::perturb(poses[h], models[h], rng, 0.02, 0.6, 0.3);
      ProjectedHand out;
      project_hand(models[h], q, camera, 0.03, &out);
      ASSERT_GE(out.hull_count, 3);
      std::vector<cv::Point2f> corners, hull;
      for (const Vec2& p : out.palm_px) corners.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
      cv::convexHull(corners, hull);
      EXPECT_EQ(out.hull_count, static_cast<int>(hull.size()));
      cv::Rect2f box = cv::boundingRect(hull);
      std::uniform_real_distribution<float> ux(box.x - 10, box.x + box.width + 10);
      std::uniform_real_distribution<float> uy(box.y - 10, box.y + box.height + 10);
      for (int k = 0; k < 400; ++k) {
        const cv::Point2f p(ux(rng), uy(rng));
        const double d = cv::pointPolygonTest(hull, p, true);  // > 0 inside
        if (std::abs(d) < 0.01) continue;
        // Only the palm: move the bones out of the way.
        ProjectedHand palm_only = out;
        for (auto& b : palm_only.bones) b.valid = false;
        const OutlineNearest n = nearest_part(palm_only, Vec2(p.x, p.y));
        EXPECT_EQ(n.bone, -1);
        EXPECT_NEAR(n.distance_px, -d, 1e-3) << "hand " << h << " at " << p;
        EXPECT_NEAR(part_distance(out, -1, Vec2(p.x, p.y)), -d, 1e-3) << "hand " << h << " at " << p;
        (d > 0 ? inside : outside) += 1;
      }
    }
  }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 100);
}

TEST(Coverage, EachHandOwnsItsOwnPixelsAndNoForearmPixels) {
  const auto models = test::model_hands();
  const auto poses = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  cv::Mat mask;
  std::array<cv::Mat, 2> own;
  for (int h = 0; h < 2; ++h) {
    test::draw_capsule_mask(models[h], poses[h], camera, &own[h]);
    test::draw_capsule_mask(models[h], poses[h], camera, &mask);
  }
  // A forearm behind each wrist, drawn into the silhouette as the camera sees it.
  RegistrationParams params;
  std::array<ProjectedHand, 2> outline;
  cv::Mat forearms = cv::Mat::zeros(mask.size(), CV_8UC1);
  for (int h = 0; h < 2; ++h) {
    const double r = bracelet_radius_m(params, models[h].shape.dimensions.width);
    project_hand(models[h], poses[h], camera, r, &outline[h]);
    const ImageCapsule& f = outline[h].forearm;
    ASSERT_TRUE(f.valid);
    const Vec2 mid = f.a + 0.3 * (f.c - f.a);  // from 3 cm past the wrist on
    cv::line(forearms, cv::Point2d(mid.x(), mid.y()), cv::Point2d(f.c.x(), f.c.y()), 255,
             static_cast<int>(2 * f.ra));
  }
  cv::bitwise_or(mask, forearms, mask);
  std::array<std::vector<OwnedPixel>, 2> owned;
  coverage_evidence(mask, {&outline[0], &outline[1]}, params, &owned);
  for (int h = 0; h < 2; ++h) {
    ASSERT_GT(owned[h].size(), 100u) << "hand " << h;
    int own_pixels = 0;
    for (const OwnedPixel& o : owned[h]) {
      const Vec2& p = o.px;
      const int x = static_cast<int>(p.x()), y = static_cast<int>(p.y());
      EXPECT_EQ(own[1 - h].at<std::uint8_t>(y, x) != 0 && own[h].at<std::uint8_t>(y, x) == 0, false)
          << "hand " << h << " owns the other hand's pixel " << p.transpose();
      own_pixels += own[h].at<std::uint8_t>(y, x) != 0 ? 1 : 0;
    }
    // Nearly everything it owns is its own drawing; the rest lies where forearm meets wrist.
    EXPECT_GT(own_pixels, static_cast<int>(0.97 * static_cast<double>(owned[h].size()))) << "hand " << h;
  }
  // The forearms' far ends are nobody's.
  int forearm_owned = 0;
  for (int h = 0; h < 2; ++h) {
    const ImageCapsule& f = outline[h].forearm;
    const Vec2 far = f.a + 0.8 * (f.c - f.a);
    for (const auto& list : owned)
      for (const OwnedPixel& o : list) forearm_owned += (o.px - far).norm() < 0.1 * (f.c - f.a).norm() ? 1 : 0;
  }
  EXPECT_EQ(forearm_owned, 0);
  // A stride of 1 samples every pixel; nothing is owned twice.
  params.coverage_stride_px = 1;
  coverage_evidence(mask, {&outline[0], &outline[1]}, params, &owned);
  EXPECT_GT(owned[0].size() + owned[1].size(), static_cast<std::size_t>(0.5 * cv::countNonZero(mask - forearms)));
  EXPECT_LE(owned[0].size() + owned[1].size(), static_cast<std::size_t>(cv::countNonZero(mask)));
}

TEST(Coverage, UncoveredPixelsPlaceThePalmTheStringsLeaveFree) {
  // The right hand's silhouette at the truth, its four fingertips from the strings (exact), no
  // bracelet, no joint-balls, no prior. Four fingertips leave the palm free to swing about them;
  // the fit starts with the wrist 12 mm off. With the coverage direction the joints must end far
  // nearer the truth than with the strings alone.
  const auto models = test::model_hands();
  const auto poses = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandModel& model = models[1];
  const hand::HandParams& truth = poses[1];
  cv::Mat mask;
  test::draw_capsule_mask(model, truth, camera, &mask);
  std::mt19937 rng(1);
  vision::BraceletObservation no_bracelet;
  const HandObservation obs = test::observe(model, truth, no_bracelet, rng, 0.0);
  const hand::HandPoints t = hand::forward_kinematics(model, truth);
  std::array<double, 2> sum{};
  for (const Vec3& shift : {Vec3(0.012, 0, 0), Vec3(0, 0.012, 0), Vec3(-0.008, 0.008, 0.006)}) {
    hand::HandParams start = truth;
    start.set_wrist(start.p_W_wrist() + shift, start.r_W_hand());
    std::array<double, 2> px{};
    for (int with_coverage = 0; with_coverage < 2; ++with_coverage) {
      RegistrationParams params;
      params.silhouette_term = with_coverage == 1;
      params.little_free = false;  // the drawn truth's little finger copies the ring
      params.joint_ball_sigma_px = 1000;  // as good as off
      params.max_iterations = 30;
      ProjectedHand outline;
      project_hand(model, start, camera, 0.03, &outline);
      std::array<std::vector<OwnedPixel>, 2> owned;
      coverage_evidence(mask, {nullptr, &outline}, params, &owned);
      ASSERT_TRUE(owned[0].empty());
      ASSERT_GT(owned[1].size(), 50u);
      ImageEvidence image;
      image.camera = &camera;
      image.coverage = &owned[1];
      const SuccessiveAdjustment solver(params);
      hand::HandParams q = start;
      // Three frames: the owners follow the fit, as they do in a tracker.
      for (int frame = 0; frame < 3; ++frame) {
        project_hand(model, q, camera, 0.03, &outline);
        coverage_evidence(mask, {nullptr, &outline}, params, &owned);
        solver.fit(model, obs, image, nullptr, &q);
      }
      px[with_coverage] = joint_px_error(hand::forward_kinematics(model, q), t, camera);
    }
    std::printf("wrist off by %.0f mm: joints %.2f px from strings alone, %.2f px with coverage\n",
                1e3 * shift.norm(), px[0], px[1]);
    // Measured: 2.00 → 1.68, 3.51 → 1.34, 5.48 → 1.73 px; the floor is the drawn mask's
    // rasterisation against the outline's exact capsules.
    EXPECT_LT(px[1], px[0]) << "shift " << shift.transpose();
    EXPECT_LT(px[1], 2.0) << "shift " << shift.transpose();
    sum[0] += px[0];
    sum[1] += px[1];
  }
  EXPECT_LT(sum[1], 0.6 * sum[0]);
}

TEST(Coverage, DegenerateInputsOwnNothingAndFitsStayFinite) {
  const auto models = test::model_hands();
  const auto poses = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  RegistrationParams params;
  params.silhouette_term = true;
  ProjectedHand outline;
  project_hand(models[1], poses[1], camera, 0.03, &outline);
  std::array<std::vector<OwnedPixel>, 2> owned;
  // No silhouette, the wrong image type, nobody drawn: nothing is owned.
  coverage_evidence(cv::Mat(), {&outline, &outline}, params, &owned);
  EXPECT_TRUE(owned[0].empty() && owned[1].empty());
  coverage_evidence(cv::Mat(camera.height(), camera.width(), CV_32FC1, cv::Scalar(1.0f)),
                    {&outline, &outline}, params, &owned);
  EXPECT_TRUE(owned[0].empty() && owned[1].empty());
  const cv::Mat full(camera.height(), camera.width(), CV_8UC1, cv::Scalar(255));
  coverage_evidence(full, {nullptr, nullptr}, params, &owned);
  EXPECT_TRUE(owned[0].empty() && owned[1].empty());
  // A hand behind the camera draws nothing and owns nothing.
  hand::HandParams behind = poses[1];
  behind.set_wrist(camera.X_WC().p - 0.2 * camera.ray_direction_W(Vec2(320, 240)), behind.r_W_hand());
  ProjectedHand hidden;
  project_hand(models[1], behind, camera, 0.03, &hidden);
  EXPECT_EQ(hidden.hull_count, 0);
  for (const ImageCapsule& c : hidden.bones) EXPECT_FALSE(c.valid);
  EXPECT_TRUE(std::isinf(nearest_part(hidden, Vec2(320, 240)).distance_px));
  coverage_evidence(full, {nullptr, &hidden}, params, &owned);
  EXPECT_TRUE(owned[1].empty());
  // A NaN pose draws nothing either.
  hand::HandParams nan_pose = poses[1];
  nan_pose[0] = std::nan("");
  project_hand(models[1], nan_pose, camera, 0.03, &hidden);
  for (const ImageCapsule& c : hidden.bones) EXPECT_FALSE(c.valid);
  // A silhouette that is everything: the fit's pull is bounded (Huber, the kMaxCoveragePoints
  // cap) and the result finite.
  coverage_evidence(full, {nullptr, &outline}, params, &owned);
  ASSERT_FALSE(owned[1].empty());
  ImageEvidence image;
  image.camera = &camera;
  image.coverage = &owned[1];
  std::mt19937 rng(2);
  vision::BraceletObservation none;
  const HandObservation obs = test::observe(models[1], poses[1], none, rng);
  hand::HandParams q = poses[1];
  const SuccessiveAdjustment solver(params);
  const FitReport rep = solver.fit(models[1], obs, image, &poses[1], &q);
  EXPECT_TRUE(q.q.allFinite());
  EXPECT_TRUE(std::isfinite(rep.cost_final));
  EXPECT_TRUE(hand::within_limits(q, models[1].limits));
}

// The forearm's outline runs from the wrist along the forearm it is given (a bent wrist), so that
// the silhouette pixels of a bent forearm go to it and not to the hand.
TEST(Coverage, TheForearmOutlineFollowsTheForearmsDirection) {
  const auto models = test::model_hands();
  const auto poses = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  const hand::HandParams& q = poses[1];
  const Vec3 wrist = q.p_W_wrist();
  const Mat3 R = hand::hand_pose(q).R.toRotationMatrix();
  for (const Vec3& bend : {Vec3(0.0, -1.0, 0.0), Vec3(0.6, -0.8, 0.0), Vec3(0.0, -0.7, 0.7)}) {
    const Vec3 forearm_H = bend.normalized();
    ProjectedHand outline;
    project_hand(models[1], q, camera, 0.03, &outline, forearm_H);
    ASSERT_TRUE(outline.forearm.valid);
    EXPECT_NEAR((outline.forearm.a - camera.project(wrist)).norm(), 0.0, 1e-9);
    // Its far end projects from a point along R·forearm_H (whatever its length).
    const Vec2 dir = (outline.forearm.c - outline.forearm.a).normalized();
    const Vec2 expected = (camera.project(wrist + 0.05 * R * forearm_H) - outline.forearm.a).normalized();
    EXPECT_GT(dir.dot(expected), 0.999) << forearm_H.transpose();
  }
}

}  // namespace
}  // namespace spidar::registration
