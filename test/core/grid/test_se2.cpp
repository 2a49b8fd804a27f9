#include <gtest/gtest.h>

#include <cmath>

#include "downstream_perception/core/grid/se2.h"

using namespace downstream_perception;  // NOLINT

namespace {
double deg(double d) {
  return d * M_PI / 180.0;
}
}  // namespace

TEST(SE2, LessonCompositionMapOdomBase) {
  const Pose2D map_odom{2.0, 1.0, deg(10)};
  const Pose2D odom_base{3.0, 0.0, deg(30)};
  const Pose2D map_base = compose(map_odom, odom_base);
  EXPECT_NEAR(map_base.x, 4.9544, 1e-4);
  EXPECT_NEAR(map_base.y, 1.5209, 1e-4);
  EXPECT_NEAR(map_base.yaw, deg(40), 1e-12);
  // The wall 4 m ahead lands at (8.0186, 4.0921), whether composed first or walked link by link.
  const Point2 a = apply(map_base, {4.0, 0.0});
  const Point2 b = apply(map_odom, apply(odom_base, {4.0, 0.0}));
  EXPECT_NEAR(a.x, 8.0186, 1e-4);
  EXPECT_NEAR(a.y, 4.0921, 1e-4);
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
}

TEST(SE2, LessonInverseTakesGoalToBase) {
  const Pose2D map_base = compose({2.0, 1.0, deg(10)}, {3.0, 0.0, deg(30)});
  const Point2 goal = apply(inverse(map_base), {8.0, 4.0});
  EXPECT_NEAR(goal.x, 3.9266, 1e-4);
  EXPECT_NEAR(goal.y, -0.0586, 1e-4);
  // Round trip is the identity.
  const Pose2D id = compose(map_base, inverse(map_base));
  EXPECT_NEAR(id.x, 0.0, 1e-12);
  EXPECT_NEAR(id.y, 0.0, 1e-12);
  EXPECT_NEAR(id.yaw, 0.0, 1e-12);
}

TEST(SE2, LessonInterpolationAtAlpha06) {
  const Pose2D p = interpolate({4.90, 1.50, deg(38)}, 1.00, {5.06, 1.62, deg(44)}, 1.10, 1.06);
  EXPECT_NEAR(p.x, 4.996, 1e-9);
  EXPECT_NEAR(p.y, 1.572, 1e-9);
  EXPECT_NEAR(p.yaw, deg(41.6), 1e-9);
}

TEST(SE2, InterpolationTakesTheShortArcAcrossTheSeam) {
  const Pose2D p = interpolate({0, 0, deg(358)}, 0.0, {0, 0, deg(4)}, 1.0, 0.6);
  EXPECT_NEAR(p.yaw, deg(1.6), 1e-9);  // not 145.6 deg
  const Pose2D q = interpolate({0, 0, deg(359)}, 0.0, {0, 0, deg(1)}, 1.0, 0.5);
  EXPECT_NEAR(std::abs(normalizeAngle(q.yaw)), 0.0, 1e-9);  // not 180 deg
}

TEST(SE2, NormalizeAngle) {
  EXPECT_NEAR(normalizeAngle(deg(361.6)), deg(1.6), 1e-12);
  EXPECT_NEAR(normalizeAngle(deg(-190)), deg(170), 1e-12);
  EXPECT_NEAR(shortestAngularDistance(deg(358), deg(4)), deg(6), 1e-12);
  EXPECT_NEAR(shortestAngularDistance(deg(4), deg(358)), deg(-6), 1e-12);
  EXPECT_GE(normalizeAngle(M_PI), -M_PI);
  EXPECT_LT(normalizeAngle(M_PI), M_PI);
}
