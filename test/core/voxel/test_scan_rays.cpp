#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "downstream_perception/core/voxel/scan_rays.h"
#include "downstream_perception/core/voxel/voxel_map.h"

using namespace downstream_perception;  // NOLINT

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Beams every 45 degrees from 0; range_min 0.1, range_max 5.
const std::vector<float> kRanges = {1.0f, kInf, std::nanf(""), -kInf, 0.05f, 7.0f, 5.0f};

LaserScanView view() {
  LaserScanView s;
  s.ranges = kRanges.data();
  s.count = kRanges.size();
  s.angle_min = 0.0;
  s.angle_increment = M_PI / 4;
  s.range_min = 0.1;
  s.range_max = 5.0;
  return s;
}

// The sensor at (1, 2, 0.5), turned 90 degrees left: its x is the world's y.
Eigen::Isometry3d pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).matrix();
  T.translation() = Eigen::Vector3d(1.0, 2.0, 0.5);
  return T;
}

void expectPoint(const std::vector<float>& v, std::size_t i, double x, double y, double z) {
  ASSERT_GE(v.size(), 3 * i + 3);
  EXPECT_NEAR(v[3 * i], x, 1e-5);
  EXPECT_NEAR(v[3 * i + 1], y, 1e-5);
  EXPECT_NEAR(v[3 * i + 2], z, 1e-5);
}

ScanRayOptions noReturn() {
  ScanRayOptions o;
  o.inf_is_no_return = true;
  return o;
}

}  // namespace

TEST(ScanRays, Rep117HandWorked) {
  DepthRays out;
  scanToRays(view(), pose(), noReturn(), &out);
  // Beam 0 (sensor +x = world +y) returns at 1 m: (1, 3, 0.5). Beam 6 (270 deg = sensor -y =
  // world +x) at range_max 5 m is a return: (6, 2, 0.5).
  ASSERT_EQ(out.hits.size(), 6u);
  expectPoint(out.hits, 0, 1.0, 3.0, 0.5);
  expectPoint(out.hits, 1, 6.0, 2.0, 0.5);
  // Beam 1 (+Inf, 45 deg): a no-return 1 m along, sensor (0.7071, 0.7071) = world (-0.7071,
  // 0.7071) from (1, 2).
  ASSERT_EQ(out.no_returns.size(), 3u);
  expectPoint(out.no_returns, 0, 1.0 - std::sqrt(0.5), 2.0 + std::sqrt(0.5), 0.5);
  // NaN, -Inf, 0.05 < range_min, 7 > range_max.
  EXPECT_EQ(out.invalid, 4u);
  // Without inf_is_no_return +Inf is skipped; with range_max_is_no_return beam 6 is a no-return
  // 1 m along world +x: (2, 2, 0.5).
  ScanRayOptions range_max;
  range_max.range_max_is_no_return = true;
  scanToRays(view(), pose(), range_max, &out);
  EXPECT_EQ(out.hits.size(), 3u);
  ASSERT_EQ(out.no_returns.size(), 3u);
  expectPoint(out.no_returns, 0, 2.0, 2.0, 0.5);
  EXPECT_EQ(out.invalid, 5u);
}

TEST(ScanRays, UpsideDownScannerMirrorsTheFan) {
  // Rolled 180 degrees: the beam at +90 degrees goes to world -y.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).matrix();
  const std::vector<float> r = {2.0f};
  LaserScanView s = view();
  s.ranges = r.data();
  s.count = 1;
  s.angle_min = M_PI / 2;
  DepthRays out;
  scanToRays(s, T, noReturn(), &out);
  expectPoint(out.hits, 0, 0.0, -2.0, 0.0);
}

TEST(ScanRays, IntoTheVoxelMapMarksAndClears) {
  // 10 cm voxels; the scanner at (0.05, 0.55, 0.55) sees a return 1 m ahead along +x.
  VoxelMapConfig c;
  c.resolution_m = 0.1;
  c.z_resolution_m = 0.1;
  c.z_voxels = 10;
  VoxelMap map(c, 0.0, 0.0, 20, 20);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.05, 0.55, 0.55);
  const std::vector<float> r = {1.0f};
  LaserScanView s = view();
  s.ranges = r.data();
  s.count = 1;
  DepthRays out;
  scanToRays(s, T, noReturn(), &out);
  VoxelRayConfig rays;
  map.integrate(T.translation(), out.hits.data(), out.hits.size() / 3, out.no_returns.data(),
                out.no_returns.size() / 3, 0.0, rays);
  EXPECT_EQ(map.state(10, 5, 5, 0.0), VoxelState::kOccupied);  // x 1.0 .. 1.1 holds 1.05
  EXPECT_EQ(map.state(5, 5, 5, 0.0), VoxelState::kFree);
  EXPECT_EQ(map.state(5, 5, 4, 0.0), VoxelState::kUnknown);  // below the beam's plane
}

TEST(ScanRays, InvalidScanRefused) {
  LaserScanView s = view();
  s.angle_increment = 0.0;
  DepthRays out;
  EXPECT_THROW(scanToRays(s, pose(), noReturn(), &out), std::invalid_argument);
  Eigen::Isometry3d T = pose();
  T.translation().x() = std::nan("");
  EXPECT_THROW(scanToRays(view(), T, noReturn(), &out), std::invalid_argument);
}

TEST(ScanRays, InfIsValidKeepsCostmap2dMeaning) {
  // costmap_2d substitutes range_max - 0.1 mm for +Inf: a return (it clears to there, and marks
  // if within obstacle_range), not a no-return. Beam 1 at 45 degrees in the sensor frame is world
  // (-0.7071, 0.7071) from (1, 2): 4.9999 m along it.
  ScanRayOptions valid;
  valid.inf_is_valid = true;
  DepthRays out;
  scanToRays(view(), pose(), valid, &out);
  ASSERT_EQ(out.hits.size(), 9u);
  EXPECT_TRUE(out.no_returns.empty());
  const double r = 5.0 - 1e-4;
  expectPoint(out.hits, 1, 1.0 - r * std::sqrt(0.5), 2.0 + r * std::sqrt(0.5), 0.5);
  // Both set: ours (a no-return) wins, as in the obstacle layer.
  valid.inf_is_no_return = true;
  scanToRays(view(), pose(), valid, &out);
  EXPECT_EQ(out.hits.size(), 6u);
  EXPECT_EQ(out.no_returns.size(), 3u);
}

TEST(ScanRays, MovingSensorInterpolatesEachBeamsPose) {
  // Three beams of 1 m at 0, -45 and -90 degrees while the sensor moves 0.6 m along the world's x
  // and turns 90 degrees left: beam 1 is taken halfway, from (0.3, 0, 0) turned 45 degrees, beam 2
  // from (0.6, 0, 0) turned 90, so every beam points along the world's +x.
  const std::vector<float> ranges = {1.0f, 1.0f, 1.0f};
  LaserScanView s;
  s.ranges = ranges.data();
  s.count = ranges.size();
  s.angle_min = 0.0;
  s.angle_increment = -M_PI / 4;
  s.range_min = 0.1;
  s.range_max = 5.0;
  const Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d last = Eigen::Isometry3d::Identity();
  last.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).matrix();
  last.translation() = Eigen::Vector3d(0.6, 0.0, 0.0);
  DepthRays rays;
  scanToRays(s, first, last, ScanRayOptions{}, &rays);
  ASSERT_EQ(rays.hits.size(), 9u);
  expectPoint(rays.hits, 0, 1.0, 0.0, 0.0);
  expectPoint(rays.hits, 1, 1.3, 0.0, 0.0);
  expectPoint(rays.hits, 2, 1.6, 0.0, 0.0);
  // The same pose twice is the still sensor's result.
  DepthRays still, same;
  scanToRays(view(), pose(), ScanRayOptions{}, &still);
  scanToRays(view(), pose(), pose(), ScanRayOptions{}, &same);
  EXPECT_EQ(still.hits, same.hits);
  Eigen::Isometry3d bad = last;
  bad.translation().x() = std::nan("");
  EXPECT_THROW(scanToRays(s, first, bad, ScanRayOptions{}, &rays), std::invalid_argument);
}
