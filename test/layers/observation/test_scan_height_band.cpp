// costmap_2d's LaserScan rules before integration: the height band on every beam's end and the
// inf_is_valid substitution.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "downstream_perception/layers/observation/scan_height_band.h"

namespace downstream_perception {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(ScanHeightBand, LevelScannerInsideTheBandKeepsEveryRange) {
  std::vector<float> r = {1.0f, 2.0f, kInf, kNaN};
  const auto s = prefilterScanRanges(&r, 0.0, 0.1, 10.0, false, 3.0, {0.3, 0.0, 0.0}, {0.0, 2.0});
  EXPECT_EQ(s.outside_band, 0u);
  EXPECT_EQ(s.inf_substituted, 0u);
  EXPECT_EQ(r[0], 1.0f);
  EXPECT_EQ(r[1], 2.0f);
  EXPECT_EQ(r[2], kInf);  // left for the integrator (ignored, or no return with ours)
  EXPECT_TRUE(std::isnan(r[3]));
}

TEST(ScanHeightBand, LevelScannerAboveTheBandDropsEveryBeam) {
  // A scanner mounted at 2.5 m with costmap_2d's default band [0, 2]: nothing marks or clears.
  std::vector<float> r = {1.0f, 2.0f, kInf};
  const auto s = prefilterScanRanges(&r, 0.0, 0.1, 10.0, false, 3.0, {2.5, 0.0, 0.0}, {0.0, 2.0});
  EXPECT_EQ(s.outside_band, 3u);
  for (float v : r) EXPECT_TRUE(std::isnan(v));
}

TEST(ScanHeightBand, TiltedScannerDropsTheBeamsThatHitTheFloor) {
  // Pitched down: the sensor's x axis has global z component -0.1. Along +x (angle 0) a return
  // at 4 m is at 0.2 - 0.4 = -0.2 m (the floor, below min 0): dropped. Along +y (angle pi/2) the
  // height stays 0.2 m: kept. Along -x (angle pi) it rises to 0.6 m: kept.
  std::vector<float> r = {4.0f, 4.0f, 4.0f};
  const auto s =
      prefilterScanRanges(&r, 0.0, M_PI / 2, 10.0, false, 3.0, {0.2, -0.1, 0.0}, {0.0, 2.0});
  EXPECT_EQ(s.outside_band, 1u);
  EXPECT_TRUE(std::isnan(r[0]));
  EXPECT_EQ(r[1], 4.0f);
  EXPECT_EQ(r[2], 4.0f);
}

TEST(ScanHeightBand, Costmap2dInfIsValidBecomesAReturnJustInsideRangeMax) {
  std::vector<float> r = {kInf, -kInf, 1.0f};
  const auto s = prefilterScanRanges(&r, 0.0, 0.1, 5.0, true, 3.0, {0.0, 0.0, 0.0}, {0.0, 2.0});
  EXPECT_EQ(s.inf_substituted, 1u);
  EXPECT_NEAR(r[0], 5.0 - kCostmap2dInfEpsilonM, 1e-6);
  EXPECT_LT(r[0], 5.0f);   // a return: inside range_max, not range_max itself
  EXPECT_EQ(r[1], -kInf);  // -Inf is never substituted (costmap_2d: positive only)
  EXPECT_EQ(r[2], 1.0f);
}

TEST(ScanHeightBand, NoReturnBeamsAreTestedWhereTheirClearingEnds) {
  // Pitched up by z/x = 0.5: at the raytrace end (3 m) a +Inf beam along +x is at 1.5 m, inside
  // [0, 2]; with a 5 m raytrace end it is at 2.5 m: dropped.
  std::vector<float> a = {kInf};
  std::vector<float> b = {kInf};
  prefilterScanRanges(&a, 0.0, 0.1, 10.0, false, 3.0, {0.0, 0.5, 0.0}, {0.0, 2.0});
  prefilterScanRanges(&b, 0.0, 0.1, 10.0, false, 5.0, {0.0, 0.5, 0.0}, {0.0, 2.0});
  EXPECT_EQ(a[0], kInf);
  EXPECT_TRUE(std::isnan(b[0]));
}

TEST(ScanHeightBand, BandEdgesAreInclusive) {
  // costmap_2d keeps z <= max_obstacle_height and z >= min_obstacle_height.
  std::vector<float> r = {1.0f};
  std::vector<float> q = {1.0f};
  prefilterScanRanges(&r, 0.0, 0.1, 10.0, false, 3.0, {2.0, 0.0, 0.0}, {0.0, 2.0});
  prefilterScanRanges(&q, 0.0, 0.1, 10.0, false, 3.0, {0.5, 0.0, 0.0}, {0.5, 2.0});
  EXPECT_EQ(r[0], 1.0f);
  EXPECT_EQ(q[0], 1.0f);
}

}  // namespace
}  // namespace downstream_perception
