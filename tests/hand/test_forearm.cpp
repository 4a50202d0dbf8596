// Where a forearm points (hand/forearm.hpp): at the elbow while the wrist can bend that far, at
// the bend limit in the plane of the hand's axis and the elbow beyond it.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "spidar/hand/forearm.hpp"
#include "spidar/hand/rotation_vector.hpp"

namespace spidar::hand {
namespace {

double bend_angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

TEST(Forearm, PointsAtTheElbowWithinTheWristsBend) {
  const Mat3 R = rotation_from_vector(Vec3(0.4, -0.9, 0.2));
  const Vec3 wrist(0.05, -0.02, 0.3);
  const Vec3 axis = -R.col(1);
  const double limit = 1.0;
  for (double bend : {0.0, 0.3, 0.7, 0.99}) {
    // An elbow `bend` away from the hand's axis, 0.25 m from the wrist, in the plane of x_H.
    const Vec3 d = Eigen::AngleAxisd(bend, R.col(0)) * axis;
    const Vec3 got = forearm_direction(R, wrist, wrist + 0.25 * d, limit);
    EXPECT_LT((got - d).norm(), 1e-12) << bend;
  }
}

TEST(Forearm, BendsNoFurtherThanTheLimitTowardTheElbow) {
  const Mat3 R = rotation_from_vector(Vec3(-0.3, 0.5, 1.2));
  const Vec3 wrist(0.0, 0.1, 0.2);
  const Vec3 axis = -R.col(1);
  const double limit = 1.05;
  for (double bend : {1.2, 2.0, 3.0}) {
    const Vec3 plane = (R.col(0) + 0.5 * R.col(2)).normalized();
    const Vec3 d = Eigen::AngleAxisd(bend, plane) * axis;
    const Vec3 got = forearm_direction(R, wrist, wrist + 0.3 * d, limit);
    EXPECT_NEAR(got.norm(), 1.0, 1e-12);
    EXPECT_NEAR(bend_angle(axis, got), limit, 1e-9) << bend;
    // On the way from the axis to the elbow: in their plane, on the elbow's side.
    EXPECT_NEAR(got.dot(plane), 0.0, 1e-9);
    EXPECT_NEAR(bend_angle(axis, got) + bend_angle(got, d), bend, 1e-9);
  }
  // An elbow at the wrist (or not finite) leaves the forearm in line with the hand.
  EXPECT_LT((forearm_direction(R, wrist, wrist, limit) - axis).norm(), 1e-12);
  EXPECT_LT((forearm_direction(R, wrist, Vec3(NAN, 0, 0), limit) - axis).norm(), 1e-12);
  EXPECT_LT((forearm_direction(R, wrist, wrist + 0.3 * Vec3(-axis), NAN) - axis).norm(), 1e-12);
  // An elbow straight ahead of the fingers: the forearm flexes by the limit about x_H.
  const Vec3 got = forearm_direction(R, wrist, wrist - 0.3 * axis, limit);
  EXPECT_NEAR(bend_angle(axis, got), limit, 1e-9);
  EXPECT_NEAR(got.dot(R.col(0)), 0.0, 1e-9);
}

TEST(Forearm, TheWristBendTakesTheHandsAxisOntoTheForearm) {
  const Mat3 R = rotation_from_vector(Vec3(1.1, 0.2, -0.6));
  const Vec3 d = Vec3(0.3, -0.8, 0.5).normalized();
  const Mat3 B = wrist_bend(R, d);
  EXPECT_LT((B * -R.col(1) - d).norm(), 1e-12);
  EXPECT_LT((B * B.transpose() - Mat3::Identity()).norm(), 1e-12);
  EXPECT_NEAR(B.determinant(), 1.0, 1e-12);
  // Shortest arc: what is perpendicular to both the axis and d stays put.
  const Vec3 n = (-R.col(1)).cross(d).normalized();
  EXPECT_LT((B * n - n).norm(), 1e-12);

  HandParams q;
  q.set_wrist(Vec3(0.1, 0.2, 0.3), Vec3(1.1, 0.2, -0.6));
  EXPECT_LT((elbow_in_line(q, 0.25) - (Vec3(0.1, 0.2, 0.3) - 0.25 * R.col(1))).norm(), 1e-12);
}

}  // namespace
}  // namespace spidar::hand
