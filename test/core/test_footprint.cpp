#include <gtest/gtest.h>

#include <cmath>

#include "downstream_perception/core/footprint.h"

using namespace downstream_perception;  // NOLINT

TEST(Footprint, SquareRadiiMatchTheAnchorScenario) {
  // costmap_2d's benchmark footprint: square +-0.25 m -> inscribed 0.25, circumscribed 0.3536.
  const Footprint square = {{0.25, 0.25}, {-0.25, 0.25}, {-0.25, -0.25}, {0.25, -0.25}};
  EXPECT_TRUE(validateFootprint(square).empty());
  EXPECT_NEAR(inscribedRadius(square), 0.25, 1e-12);
  EXPECT_NEAR(circumscribedRadius(square), 0.353553, 1e-6);
  const Footprint padded = padFootprint(square, 0.05);
  EXPECT_NEAR(inscribedRadius(padded), 0.30, 1e-12);
}

TEST(Footprint, OffCentreRectangleAndCircle) {
  // A 1.0 x 0.6 m robot whose base_link sits 0.2 m behind the centre.
  const Footprint rect = {{0.7, 0.3}, {-0.3, 0.3}, {-0.3, -0.3}, {0.7, -0.3}};
  EXPECT_NEAR(inscribedRadius(rect), 0.3, 1e-12);
  EXPECT_NEAR(circumscribedRadius(rect), std::hypot(0.7, 0.3), 1e-12);
  const Footprint circle = circularFootprint(0.46);
  EXPECT_EQ(circle.size(), 16u);
  EXPECT_NEAR(circumscribedRadius(circle), 0.46, 1e-12);
  EXPECT_NEAR(inscribedRadius(circle), 0.46 * std::cos(M_PI / 16), 1e-12);
}

TEST(Footprint, RejectsDegenerateOrAbsurdPolygons) {
  EXPECT_FALSE(validateFootprint({{0, 0}, {1, 0}}).empty());
  EXPECT_FALSE(validateFootprint({{0, 0}, {1, 0}, {NAN, 1}}).empty());
  EXPECT_FALSE(validateFootprint({{0, 0}, {1e6, 0}, {0, 1}}).empty());
}
