#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/voxel/depth_rays.h"
#include "downstream_perception/core/voxel/voxel_map.h"

using namespace downstream_perception;  // NOLINT
using cost::kFreeSpace;
using cost::kLethalObstacle;
using cost::kNoInformation;

namespace {

// ln(0.7 / 0.3) and ln(0.4 / 0.6): the default hit and miss.
constexpr double kHit = 0.8472978603872037;
constexpr double kMiss = -0.4054651081081644;

// 10 cm voxels in x, y and z: 40 x 40 columns of 20 voxels (0 to 2 m), band from 0.1 m (the floor
// voxel, centre 0.05 m, is outside it: floor returns mark in 3-D but never reach the costmap).
VoxelMapConfig roomConfig() {
  VoxelMapConfig c;
  c.resolution_m = 0.1;
  c.z_resolution_m = 0.1;
  c.z_voxels = 20;
  c.min_obstacle_height_m = 0.1;
  c.max_obstacle_height_m = 1.9;
  return c;
}

VoxelRayConfig longRays() {
  VoxelRayConfig r;
  r.obstacle_max_range_m = 10.0;
  r.raytrace_max_range_m = 10.0;
  r.no_return_range_m = 10.0;
  return r;
}

void add(std::vector<float>* pts, double x, double y, double z) {
  pts->push_back(static_cast<float>(x));
  pts->push_back(static_cast<float>(y));
  pts->push_back(static_cast<float>(z));
}

VoxelIntegrationStats integrate(VoxelMap* map, const Eigen::Vector3d& origin,
                                const std::vector<float>& hits, double t,
                                const VoxelRayConfig& rays = longRays()) {
  return map->integrate(origin, hits.data(), hits.size() / 3, nullptr, 0, t, rays);
}

std::uint8_t costAt(const VoxelMap& map, int x, int y, double t) {
  return map.columnCost(map.column(x, y, t));
}

}  // namespace

TEST(VoxelMap, OneHitAndOneMissHandWorked) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  add(&pts, 2.05, 0.55, 0.55);  // voxel (20, 5, 5)
  const Eigen::Vector3d origin(0.05, 0.55, 0.55);
  const auto s = integrate(&map, origin, pts, 10.0);
  EXPECT_EQ(s.rays, 1u);
  EXPECT_EQ(s.marked, 1u);
  EXPECT_EQ(s.cleared, 20u);  // voxels 0..19 along x, the end voxel excluded
  EXPECT_EQ(s.voxels_walked, 20u);
  EXPECT_NEAR(map.logOdds(20, 5, 5, 10.0), kHit, 1e-6);
  EXPECT_NEAR(map.logOdds(7, 5, 5, 10.0), kMiss, 1e-6);
  EXPECT_EQ(map.state(20, 5, 5, 10.0), VoxelState::kOccupied);
  EXPECT_EQ(map.state(7, 5, 5, 10.0), VoxelState::kFree);
  EXPECT_EQ(map.state(7, 6, 5, 10.0), VoxelState::kUnknown);
  // A second frame whose return lies beyond: the old hit is crossed once, 0.847 - 0.405 = 0.442,
  // not above the occupied threshold 0.5 any more.
  pts.clear();
  add(&pts, 3.05, 0.55, 0.55);
  integrate(&map, origin, pts, 11.0);
  EXPECT_NEAR(map.logOdds(20, 5, 5, 11.0), kHit + kMiss, 1e-6);
  EXPECT_EQ(map.state(20, 5, 5, 11.0), VoxelState::kUnknown);
  // The clamp: five more hits stop at 3.5.
  for (int k = 0; k < 5; ++k) integrate(&map, origin, pts, 12.0 + k);
  EXPECT_NEAR(map.logOdds(30, 5, 5, 20.0), 3.5, 1e-6);
}

TEST(VoxelMap, EachVoxelOnceAFrameHitsFirst) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  // Forty rays through the same voxels, and one ray ending in voxel (10, 5, 5) that the others
  // cross: the voxel stays a hit, the shared voxels get one miss each.
  for (int k = 0; k < 40; ++k) add(&pts, 3.05, 0.55, 0.55);
  add(&pts, 1.05, 0.55, 0.55);
  const auto s = integrate(&map, Eigen::Vector3d(0.05, 0.55, 0.55), pts, 0.0);
  EXPECT_EQ(s.marked, 2u);
  EXPECT_EQ(s.cleared, 29u);  // voxels 0..29 without 10
  EXPECT_NEAR(map.logOdds(10, 5, 5, 0.0), kHit, 1e-6);
  EXPECT_NEAR(map.logOdds(5, 5, 5, 0.0), kMiss, 1e-6);
  // Every ray walked: 40 x 30 voxels (0..29) + 10 (0..9).
  EXPECT_EQ(s.voxels_walked, 40u * 30u + 10u);
}

TEST(VoxelMap, OneRayPerEndVoxel) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  for (int k = 0; k < 40; ++k) add(&pts, 3.05 + 0.001 * k, 0.55, 0.55);  // all in voxel 30
  add(&pts, 1.05, 0.55, 0.55);
  VoxelRayConfig r = longRays();
  r.one_ray_per_end_voxel = true;
  const auto s = integrate(&map, Eigen::Vector3d(0.05, 0.55, 0.55), pts, 0.0, r);
  // One ray to voxel 30 (30 visits) and the one to voxel 10 (10): the same marks and misses.
  EXPECT_EQ(s.voxels_walked, 40u);
  EXPECT_EQ(s.marked, 2u);
  EXPECT_EQ(s.cleared, 29u);
  // The next frame casts again.
  EXPECT_EQ(integrate(&map, Eigen::Vector3d(0.05, 0.55, 0.55), pts, 1.0, r).voxels_walked, 40u);
}

TEST(VoxelMap, ColumnRuleFollowsCostmap2d) {
  VoxelMapConfig c = roomConfig();
  c.mark_threshold = 1;
  c.unknown_threshold = 3;
  VoxelMap map(c, 0.0, 0.0, 40, 40);
  // Band [0.1, 1.9] m: voxels 1..18 (centres 0.15 .. 1.85 m); an unseen column has 18 unknown.
  EXPECT_EQ(map.bandFirst(), 1);
  EXPECT_EQ(map.bandLast(), 18);
  EXPECT_EQ(costAt(map, 3, 3, 0.0), kNoInformation);
  // One occupied voxel: not more than mark_threshold 1.
  std::vector<float> pts;
  add(&pts, 0.35, 0.35, 0.55);
  integrate(&map, Eigen::Vector3d(0.35, 0.35, 1.75), pts, 0.0);
  const VoxelColumn col = map.column(3, 3, 0.0);
  EXPECT_EQ(col.occupied, 1);
  // Cleared from z 1.75 down to the hit: voxels 6..17 free (12), voxel 5 occupied; band 1..18
  // leaves 1..4 and 18 unknown: 5 > 3.
  EXPECT_EQ(col.unknown, 5);
  EXPECT_EQ(costAt(map, 3, 3, 0.0), kNoInformation);
  pts.clear();
  add(&pts, 0.35, 0.35, 0.15);
  add(&pts, 0.35, 0.35, 0.25);
  integrate(&map, Eigen::Vector3d(0.35, 0.35, 1.85), pts, 1.0);
  // Now voxels 1 and 2 are hits, 3..18 were crossed (voxel 5's hit lost one miss: 0.442,
  // unknown): occupied 2 > 1.
  EXPECT_EQ(map.column(3, 3, 1.0).occupied, 2);
  EXPECT_EQ(costAt(map, 3, 3, 1.0), kLethalObstacle);
}

TEST(VoxelMap, UnknownCountIncludesCostmap2dsUnreachableBits) {
  // costmap_2d VoxelLayer's defaults: 10 voxels of 0.2 m, unknown_threshold 15. Its column word
  // has 16 bits; the 6 above z_voxels never become known, so an untouched column counts 16
  // unknown (> 15: NO_INFORMATION) and one known voxel makes it free (15).
  VoxelMapConfig c;
  c.resolution_m = 0.1;
  VoxelMap map(c, 0.0, 0.0, 20, 20);
  EXPECT_EQ(map.bandFirst(), 0);
  EXPECT_EQ(map.bandLast(), 9);
  EXPECT_EQ(map.unknownCount(VoxelColumn{0, 10}), 16);
  EXPECT_EQ(map.unknownCount(VoxelColumn{0, 9}), 15);
  EXPECT_EQ(costAt(map, 5, 5, 0.0), kNoInformation);
  std::vector<std::uint8_t> project;
  map.project(0.0, &project);
  EXPECT_EQ(project[5 * 20 + 5], kNoInformation);
  // A ray at z 0.1 m (voxel 0) from x 0.05 to a return at x 1.05: voxels x 0..9 of row y 5 are
  // crossed (0 .. 9 free), x 10 marked.
  std::vector<float> pts;
  add(&pts, 1.05, 0.55, 0.1);
  integrate(&map, Eigen::Vector3d(0.05, 0.55, 0.1), pts, 0.0);
  EXPECT_EQ(map.column(5, 5, 0.0).unknown, 9);
  EXPECT_EQ(costAt(map, 5, 5, 0.0), kFreeSpace);
  EXPECT_EQ(costAt(map, 10, 5, 0.0), kLethalObstacle);
  EXPECT_EQ(costAt(map, 5, 6, 0.0), kNoInformation);  // the row beside: untouched
  // TurtleBot 2's move_base config: 2 voxels, threshold 15: 14 bits never known, so one known
  // voxel of two makes the column free (14 + 1 = 15), none leaves it unknown (16).
  c.z_voxels = 2;
  c.max_obstacle_height_m = 0.6;
  VoxelMap low(c, 0.0, 0.0, 20, 20);
  EXPECT_EQ(low.unknownCount(VoxelColumn{0, 2}), 16);
  EXPECT_EQ(low.unknownCount(VoxelColumn{0, 1}), 15);
  // A band of more than 16 voxels (ours) counts its own unknown voxels only.
  c.z_voxels = 40;
  c.z_resolution_m = 0.05;
  c.max_obstacle_height_m = 2.0;
  VoxelMap tall(c, 0.0, 0.0, 20, 20);
  EXPECT_EQ(tall.bandLast() - tall.bandFirst() + 1, 40);
  EXPECT_EQ(tall.unknownCount(VoxelColumn{0, 40}), 40);
}

TEST(VoxelMap, TableTopStaysWhileTheFloorUnderItIsSeen) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  // A table top at z 0.70 .. 0.80 over x, y in [1.5, 2.5] m (voxel layer 7).
  std::vector<float> top;
  for (double x = 1.52; x < 2.5; x += 0.025) {
    for (double y = 1.52; y < 2.5; y += 0.025) add(&top, x, y, 0.75);
  }
  // Seen once from above (a camera on a mast).
  integrate(&map, Eigen::Vector3d(1.0, 2.0, 1.9), top, 0.0);
  ASSERT_EQ(costAt(map, 20, 20, 0.0), kLethalObstacle);
  // Then 20 frames of a low camera (0.4 m) seeing the floor under the table: every ray passes
  // under the top. In 2-D these rays cross the table's columns and would clear them.
  // The floor from x 1 to 3.5 m, y 1 to 3 m: under the table and beyond it (rays to the floor
  // beyond reach the low voxels under the table's far edge).
  std::vector<float> floor;
  for (double x = 1.01; x < 3.5; x += 0.02) {
    for (double y = 1.01; y < 3.0; y += 0.02) add(&floor, x, y, 0.02);
  }
  const Eigen::Vector3d low(0.3, 2.0, 0.4);
  for (int k = 1; k <= 20; ++k) integrate(&map, low, floor, k);
  for (int x = 15; x < 25; ++x) {
    for (int y = 15; y < 25; ++y) {
      EXPECT_EQ(map.state(x, y, 7, 20.0), VoxelState::kOccupied) << x << ", " << y;
      EXPECT_EQ(costAt(map, x, y, 20.0), kLethalObstacle) << x << ", " << y;
      // The space under the top, on the low rays' way to the floor, is free.
      EXPECT_EQ(map.state(x, y, 1, 20.0), VoxelState::kFree) << x << ", " << y;
    }
  }
  // In front of the table (x 1.0 .. 1.1) the low rays cross voxel 2 (z 0.2 .. 0.3): free, and
  // nothing there is lethal.
  EXPECT_EQ(map.state(10, 20, 2, 20.0), VoxelState::kFree);
  EXPECT_NE(costAt(map, 10, 20, 20.0), kLethalObstacle);
}

TEST(VoxelMap, OverhangAboveTheBandIsIgnored) {
  VoxelMapConfig c = roomConfig();
  c.z_voxels = 30;  // up to 3 m
  c.max_obstacle_height_m = 2.0;
  VoxelMap map(c, 0.0, 0.0, 40, 40);
  std::vector<float> shelf;
  for (double x = 2.01; x < 2.5; x += 0.03) {
    for (double y = 1.01; y < 1.5; y += 0.03) add(&shelf, x, y, 2.25);
  }
  integrate(&map, Eigen::Vector3d(0.5, 1.2, 1.5), shelf, 0.0);
  EXPECT_EQ(map.state(22, 12, 22, 0.0), VoxelState::kOccupied);  // kept in 3-D
  EXPECT_EQ(map.column(22, 12, 0.0).occupied, 0);
  EXPECT_NE(costAt(map, 22, 12, 0.0), kLethalObstacle);
  // With the band raised to 2.5 m the same voxel is lethal.
  c.max_obstacle_height_m = 2.5;
  VoxelMap high(c, 0.0, 0.0, 40, 40);
  integrate(&high, Eigen::Vector3d(0.5, 1.2, 1.5), shelf, 0.0);
  EXPECT_EQ(costAt(high, 22, 12, 0.0), kLethalObstacle);
}

TEST(VoxelMap, PersonWalkingAwayIsClearedIn3d) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  // A head-height camera: rays down to the floor reach the low voxels, rays to the wall the high
  // ones.
  const Eigen::Vector3d eye(0.05, 2.0, 1.8);
  // The person's front (x = px + 0.02) 0.4 m wide (y 1.8 .. 2.2), z 0.11 .. 1.69 m; a wall at
  // x = 3.82 behind, z up to 1.99 m; the floor (z = 0.02) in front of the wall, hidden behind the
  // person.
  const auto scene = [](double px) {
    std::vector<float> pts;
    const auto person = [](double y) { return y > 1.8 && y < 2.2; };
    for (double y = 1.01; y < 3.0; y += 0.01) {
      for (double z = 0.11; z < 1.7; z += 0.01) {
        if (person(y)) add(&pts, px + 0.02, y, z);
      }
      for (double z = 0.11; z < 2.0; z += 0.02) {
        if (!person(y)) add(&pts, 3.82, y, z);
      }
      for (double x = 0.31; x < 3.8; x += 0.02) {
        if (!person(y) || x < px) add(&pts, x, y, 0.02);
      }
    }
    return pts;
  };
  const auto at_2 = scene(2.0);
  for (int k = 0; k < 3; ++k) integrate(&map, eye, at_2, k);
  // Three hits: 2.542; the column at x = 2.0 .. 2.1 (voxel 20), y = 2.0 .. 2.1 is lethal.
  EXPECT_NEAR(map.logOdds(20, 20, 10, 2.0), 3 * kHit, 1e-5);
  EXPECT_EQ(costAt(map, 20, 20, 2.0), kLethalObstacle);
  // The person walks on to x = 3: rays to the person and to the wall cross the old place. One
  // miss per frame: after 5 frames 2.542 - 5 * 0.405 = 0.514 > 0.5 still occupied; after 6,
  // 0.109: unknown, the column is not lethal; after 8, -0.702 < -0.3: free.
  const auto at_3 = scene(3.0);
  for (int k = 3; k < 8; ++k) integrate(&map, eye, at_3, k);
  EXPECT_NEAR(map.logOdds(20, 20, 10, 8.0), 3 * kHit + 5 * kMiss, 1e-5);
  EXPECT_EQ(costAt(map, 20, 20, 8.0), kLethalObstacle);
  integrate(&map, eye, at_3, 8);
  EXPECT_EQ(map.state(20, 20, 10, 9.0), VoxelState::kUnknown);
  EXPECT_NE(costAt(map, 20, 20, 9.0), kLethalObstacle);
  for (int k = 9; k < 11; ++k) integrate(&map, eye, at_3, k);
  for (int z = 1; z < 17; ++z) {
    EXPECT_EQ(map.state(20, 20, z, 11.0), VoxelState::kFree) << z;
  }
  EXPECT_EQ(costAt(map, 30, 20, 11.0), kLethalObstacle);  // the person's new place
}

TEST(VoxelMap, DecayHandWorked) {
  VoxelMapConfig c = roomConfig();
  c.decay_time_s = 2.0;
  VoxelMap map(c, 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  add(&pts, 1.05, 1.05, 0.55);
  const Eigen::Vector3d origin(1.05, 1.05, 1.55);  // straight down: 9 misses above the hit
  integrate(&map, origin, pts, 100.0);
  EXPECT_NEAR(map.logOdds(10, 10, 5, 100.0), kHit, 1e-6);
  // exp(-0.5 / 2) = 0.7788: 0.6599, still occupied (> 0.5).
  EXPECT_NEAR(map.logOdds(10, 10, 5, 100.5), kHit * std::exp(-0.25), 1e-6);
  EXPECT_EQ(costAt(map, 10, 10, 100.5), kLethalObstacle);
  // After tau * ln 2 = 1.386 s half is left: 0.4236, unknown.
  const double half = 100.0 + 2.0 * std::log(2.0);
  EXPECT_NEAR(map.logOdds(10, 10, 5, half), kHit / 2.0, 1e-5);
  EXPECT_NE(costAt(map, 10, 10, half), kLethalObstacle);
  // A hit then adds to the decayed value: 0.4236 + 0.8473 = 1.2709.
  integrate(&map, origin, pts, half);
  EXPECT_NEAR(map.logOdds(10, 10, 5, half), 1.5 * kHit, 1e-5);
  // Long after, every voxel is unknown: pruning frees the blocks.
  EXPECT_GT(map.blocks(), 0u);
  // One second later the hit (0.771) and the misses of both frames (-0.369) are still known.
  EXPECT_EQ(map.prune(half + 1.0), 0u);
  const std::size_t blocks = map.blocks();
  EXPECT_EQ(map.prune(half + 100.0), blocks);
  EXPECT_EQ(map.blocks(), 0u);
}

TEST(VoxelMap, MemoryBoundDropsAndCounts) {
  VoxelMapConfig c = roomConfig();
  c.max_memory_mib = 0.01;  // 10485 bytes: a table of 5 x 5 x 3 pointers (600) and one block
  VoxelMap map(c, 0.0, 0.0, 40, 40);
  EXPECT_EQ(sizeof(VoxelBlock), 512u * 16u);
  EXPECT_EQ(map.maxBlocks(), 1u);  // (10485 - 600) / 8192 = 1.2
  std::vector<float> pts;
  add(&pts, 0.35, 0.35, 0.35);  // block (0, 0, 0)
  add(&pts, 2.05, 2.05, 0.35);  // block (2, 2, 0)
  const auto s = integrate(&map, Eigen::Vector3d(0.35, 0.35, 0.45), pts, 0.0);
  EXPECT_EQ(map.blocks(), 1u);
  EXPECT_GT(s.dropped_updates, 0u);
  EXPECT_EQ(map.memoryBytes(), sizeof(VoxelBlock) + 5 * 5 * 3 * sizeof(void*));
}

TEST(VoxelMap, RollingWindowKeepsWorldVoxels) {
  VoxelMap map(roomConfig(), -2.0, -2.0, 40, 40);
  std::vector<float> pts;
  add(&pts, 0.05, 0.05, 0.55);  // world voxel (20, 20, 5) from the anchor
  integrate(&map, Eigen::Vector3d(0.05, 0.05, 1.05), pts, 0.0);
  EXPECT_EQ(map.state(20, 20, 5, 0.0), VoxelState::kOccupied);
  map.setWindow(13, -3, 40, 40);  // the robot moved 1.3 m in x, -0.3 m in y
  EXPECT_NEAR(map.windowOriginX(), -0.7, 1e-12);
  EXPECT_EQ(map.state(7, 23, 5, 0.0), VoxelState::kOccupied);
  map.setWindow(25, 0, 40, 40);  // the voxel left the window: forgotten
  map.setWindow(13, -3, 40, 40);
  EXPECT_EQ(map.state(7, 23, 5, 0.0), VoxelState::kUnknown);
  EXPECT_THROW(map.setWindow(0, 0, 0, 10), std::invalid_argument);
  EXPECT_THROW(map.setWindow((1 << 30) + 1, 0, 10, 10), std::invalid_argument);
}

TEST(VoxelMap, InvalidInputIsRefusedNotCrashedOn) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  VoxelMapConfig c;
  EXPECT_EQ(c.validate(), "");
  c.z_resolution_m = nan;
  EXPECT_NE(c.validate().find("z_resolution_m"), std::string::npos);
  c = VoxelMapConfig();
  c.z_voxels = 0;
  EXPECT_NE(c.validate().find("z_voxels"), std::string::npos);
  c = VoxelMapConfig();
  c.min_obstacle_height_m = 3.0;  // above the 2 m column: no voxel in the band
  c.max_obstacle_height_m = 4.0;
  EXPECT_NE(c.validate().find("no voxel centre"), std::string::npos);
  c = VoxelMapConfig();
  c.max_memory_mib = inf;
  EXPECT_NE(c.validate().find("max_memory_mib"), std::string::npos);
  c = VoxelMapConfig();
  c.log_odds.p_hit = 0.2;
  EXPECT_NE(c.validate().find("p_hit"), std::string::npos);
  c = VoxelMapConfig();
  c.decay_time_s = -1.0;
  EXPECT_THROW(VoxelMap(c, 0.0, 0.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(VoxelMap(VoxelMapConfig(), nan, 0.0, 10, 10), std::invalid_argument);
  EXPECT_THROW(VoxelMap(VoxelMapConfig(), 0.0, 0.0, 100000, 10), std::invalid_argument);
  // 65536^2 columns: 8192 x 8192 x 2 block pointers, 1 GiB, beyond the default 64 MiB.
  EXPECT_THROW(VoxelMap(VoxelMapConfig(), 0.0, 0.0, 65536, 65536), std::invalid_argument);
  VoxelRayConfig r;
  r.raytrace_max_range_m = -1.0;
  EXPECT_NE(r.validate().find("raytrace_max_range_m"), std::string::npos);

  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  add(&pts, nan, 1.0, 1.0);
  add(&pts, inf, 1.0, 1.0);
  add(&pts, 1e30, 1.0, 1.0);  // far: clears to the range, marks nothing
  add(&pts, 1.0, 1.0, 1.0);   // at the origin: no direction
  const Eigen::Vector3d o(1.0, 1.0, 1.0);
  const auto s = integrate(&map, o, pts, 0.0);
  EXPECT_EQ(s.invalid_points, 3u);
  EXPECT_EQ(s.marked, 0u);
  EXPECT_GT(s.cleared, 0u);
  EXPECT_THROW(integrate(&map, Eigen::Vector3d(nan, 0, 0), pts, 0.0), std::invalid_argument);
  EXPECT_THROW(integrate(&map, o, pts, inf), std::invalid_argument);
  EXPECT_THROW(integrate(&map, o, pts, 0.0, r), std::invalid_argument);
  EXPECT_THROW(map.integrate(o, nullptr, 3, nullptr, 0, 0.0, longRays()), std::invalid_argument);
  EXPECT_EQ(integrate(&map, o, {}, 1.0).rays, 0u);  // empty frame
}

TEST(VoxelMap, NoReturnRaysClearToTheirRange) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> wall;
  add(&wall, 1.55, 0.55, 0.55);
  const Eigen::Vector3d o(0.05, 0.55, 0.55);
  integrate(&map, o, wall, 0.0);
  ASSERT_EQ(map.state(15, 5, 5, 0.0), VoxelState::kOccupied);
  // A no-return ray (its point only gives the direction) clears 1.2 m: voxels 0..12 (x 0.05 ..
  // 1.25), the end voxel included; the wall at 1.5 m is beyond it.
  std::vector<float> dir;
  add(&dir, 0.15, 0.55, 0.55);
  VoxelRayConfig r = longRays();
  r.no_return_range_m = 1.2;
  const auto s = map.integrate(o, nullptr, 0, dir.data(), 1, 1.0, r);
  EXPECT_EQ(s.cleared, 13u);
  EXPECT_EQ(map.state(15, 5, 5, 1.0), VoxelState::kOccupied);
  r.no_return_range_m = 3.0;
  map.integrate(o, nullptr, 0, dir.data(), 1, 2.0, r);
  EXPECT_NEAR(map.logOdds(15, 5, 5, 2.0), kHit + kMiss, 1e-6);
}

TEST(DepthRays, BackProjectionHandWorked) {
  PinholeCamera cam;
  cam.width = 2;
  cam.height = 2;
  cam.fx = 2.0;
  cam.fy = 4.0;
  cam.cx = 0.5;
  cam.cy = 0.5;
  const float inf = std::numeric_limits<float>::infinity();
  const float depth[4] = {2.0f, inf, 0.0f, std::numeric_limits<float>::quiet_NaN()};
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  DepthRays out;
  depthToRays(depth, cam, pose, false, 1, &out);
  // Pixel (0, 0) at 2 m: ((0 - 0.5) / 2 * 2, (0 - 0.5) / 4 * 2, 2) + (1, 0, 0) = (0.5, -0.25, 2).
  ASSERT_EQ(out.hits.size(), 3u);
  EXPECT_FLOAT_EQ(out.hits[0], 0.5f);
  EXPECT_FLOAT_EQ(out.hits[1], -0.25f);
  EXPECT_FLOAT_EQ(out.hits[2], 2.0f);
  // Pixel (1, 0) is +Inf: direction (0.25, -0.125, 1) normalised, 1 m from the origin.
  ASSERT_EQ(out.no_returns.size(), 3u);
  const double n = std::sqrt(0.25 * 0.25 + 0.125 * 0.125 + 1.0);
  EXPECT_NEAR(out.no_returns[0], 1.0 + 0.25 / n, 1e-6);
  EXPECT_NEAR(out.no_returns[2], 1.0 / n, 1e-6);
  EXPECT_EQ(out.invalid, 2u);  // 0 (not a no-return by default) and NaN
  depthToRays(depth, cam, pose, true, 1, &out);
  EXPECT_EQ(out.no_returns.size(), 6u);
  EXPECT_EQ(out.invalid, 1u);
  cam.fx = std::nan("");
  EXPECT_THROW(depthToRays(depth, cam, pose, false, 1, &out), std::invalid_argument);
}

TEST(VoxelMap, ClearColumnsFreesTheBandOnly) {
  // roomConfig: band voxels 1..18 of 20. A column with a hit at voxel 5 and one at voxel 19
  // (above the band): clearing it frees voxels 1..18 (the hit included) and keeps voxel 19.
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  add(&pts, 0.35, 0.35, 0.55);
  add(&pts, 0.35, 0.35, 1.95);
  integrate(&map, Eigen::Vector3d(0.35, 0.35, 1.0), pts, 0.0);
  ASSERT_EQ(map.state(3, 3, 5, 0.0), VoxelState::kOccupied);
  ASSERT_EQ(costAt(map, 3, 3, 0.0), kLethalObstacle);
  const auto s = map.clearColumns({{3, 3}, {-1, 3}, {40, 0}}, 1.0);
  EXPECT_EQ(s.cleared, 18u);  // voxels 1..18; the columns outside the window are skipped
  for (int z = 1; z <= 18; ++z) EXPECT_EQ(map.state(3, 3, z, 1.0), VoxelState::kFree) << z;
  EXPECT_EQ(map.state(3, 3, 19, 1.0), VoxelState::kOccupied);
  EXPECT_EQ(costAt(map, 3, 3, 1.0), kFreeSpace);
  EXPECT_EQ(s.touched.min_x, 3);
  EXPECT_EQ(s.touched.max_y, 3);
  // Already at the floor and nothing decays: no rewrite, nothing touched.
  const auto again = map.clearColumns({{3, 3}}, 2.0);
  EXPECT_EQ(again.cleared, 0u);
  EXPECT_TRUE(again.touched.empty());
  EXPECT_THROW(map.clearColumns({{3, 3}}, std::nan("")), std::invalid_argument);
}

TEST(VoxelMap, HeightBandDropsPointsOutsideItOnly) {
  // costmap_2d's source band [0.25, 0.35] m: below, above and inside; NaN kept for the count.
  std::vector<float> pts;
  add(&pts, 1.0, 0.0, 0.10);
  add(&pts, 2.0, 0.0, 0.30);
  add(&pts, 3.0, 0.0, 0.50);
  add(&pts, 4.0, 0.0, std::nan(""));
  add(&pts, 5.0, 0.0, 0.25);  // on the edge: kept, as costmap_2d keeps z == min
  EXPECT_EQ(dropOutsideHeightBand(&pts, 0.25, 0.35), 2u);
  ASSERT_EQ(pts.size(), 9u);
  EXPECT_FLOAT_EQ(pts[0], 2.0f);
  EXPECT_TRUE(std::isnan(pts[5]));
  EXPECT_FLOAT_EQ(pts[6], 5.0f);
}

TEST(VoxelMap, WindowProjectionMatchesTheFullOneInsideAndLeavesTheRest) {
  VoxelMap map(roomConfig(), 0.0, 0.0, 40, 40);
  std::vector<float> pts;
  for (int k = 0; k < 40; ++k) add(&pts, 3.05, 0.05 + 0.1 * k, 0.55);  // a wall at x 3.05 m
  integrate(&map, Eigen::Vector3d(0.55, 2.05, 0.55), pts, 0.0);
  std::vector<std::uint8_t> full;
  map.project(0.0, &full);
  std::vector<std::uint8_t> part(40 * 40, 7);  // 7: no cost value, must survive outside
  map.project(0.0, CellBounds{25, 10, 34, 29}, &part);
  for (int y = 0; y < 40; ++y) {
    for (int x = 0; x < 40; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * 40 + x;
      const bool inside = x >= 25 && x <= 34 && y >= 10 && y <= 29;
      EXPECT_EQ(part[i], inside ? full[i] : 7) << x << ", " << y;
    }
  }
  EXPECT_EQ(part[20 * 40 + 30], kLethalObstacle);  // the wall's column in the window
  // A window partly outside is clipped; an empty one changes nothing; a wrong size is resized.
  map.project(0.0, CellBounds{-5, -5, 2, 2}, &part);
  EXPECT_EQ(part[0], full[0]);
  const std::vector<std::uint8_t> before = part;
  map.project(0.0, CellBounds{}, &part);
  EXPECT_EQ(part, before);
  std::vector<std::uint8_t> small(3, 1);
  map.project(0.0, CellBounds{0, 0, 0, 0}, &small);
  ASSERT_EQ(small.size(), 1600u);
  EXPECT_EQ(small[0], full[0]);
}
