// Frustum clearing of depth frames (VoxelMap::integrateDepthFrustum), hand-worked on a camera
// that looks along +x: which voxels a frame clears, which it keeps.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "downstream_perception/core/voxel/voxel_map.h"

using namespace downstream_perception;  // NOLINT

namespace {

constexpr double kHit = 0.8472978603872037;    // ln(0.7 / 0.3)
constexpr double kMiss = -0.4054651081081644;  // ln(0.4 / 0.6)
constexpr float kInf = std::numeric_limits<float>::infinity();

// 10 cm voxels, 40 x 40 columns of 20 (0 to 2 m).
VoxelMapConfig config() {
  VoxelMapConfig c;
  c.resolution_m = 0.1;
  c.z_resolution_m = 0.1;
  c.z_voxels = 20;
  return c;
}

VoxelRayConfig rays(double range = 10.0) {
  VoxelRayConfig r;
  r.obstacle_max_range_m = range;
  r.raytrace_max_range_m = range;
  r.no_return_range_m = range;
  return r;
}

// 41 x 41 pixels, f = 40 px (half angle ~27 degrees), at (0.55, 2.05, 1.05) looking along +x:
// optical z = world +x, optical x = world -y, optical y = world -z.
PinholeCamera camera() {
  PinholeCamera c;
  c.fx = c.fy = 40.0;
  c.cx = c.cy = 20.0;
  c.width = c.height = 41;
  return c;
}

Eigen::Isometry3d pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0.55, 2.05, 1.05);
  return T;
}

struct Box {
  Eigen::Vector3d lo, hi;
};

// Depth (optical z) of each pixel: the nearest of the boxes and the wall x = wall_x, or +Inf.
std::vector<float> render(const std::vector<Box>& boxes, double wall_x) {
  const PinholeCamera c = camera();
  const Eigen::Isometry3d T = pose();
  std::vector<float> depth(static_cast<std::size_t>(c.width) * c.height, kInf);
  for (int v = 0; v < c.height; ++v) {
    for (int u = 0; u < c.width; ++u) {
      const Eigen::Vector3d ray((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0);
      const Eigen::Vector3d d = T.linear() * ray;  // world, optical z = 1 per unit
      double best = std::isfinite(wall_x) ? (wall_x - T.translation().x()) / d.x() : 1e300;
      for (const Box& b : boxes) {
        double t0 = 0.0, t1 = 1e300;
        for (int a = 0; a < 3; ++a) {
          if (std::abs(d[a]) < 1e-12) {
            if (T.translation()[a] < b.lo[a] || T.translation()[a] > b.hi[a]) t0 = 1e301;
            continue;
          }
          double ta = (b.lo[a] - T.translation()[a]) / d[a];
          double tb = (b.hi[a] - T.translation()[a]) / d[a];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (t0 <= t1 && t0 < best) best = t0;
      }
      if (best < 1e299) depth[static_cast<std::size_t>(v) * c.width + u] = static_cast<float>(best);
    }
  }
  return depth;
}

// Marks voxel (x, y, z) with one hit from a frame without clearing.
void mark(VoxelMap* map, int x, int y, int z, double t) {
  VoxelRayConfig r = rays();
  r.clearing = false;
  const std::vector<float> p = {static_cast<float>(0.1 * x + 0.05),
                                static_cast<float>(0.1 * y + 0.05),
                                static_cast<float>(0.1 * z + 0.05)};
  map->integrate(Eigen::Vector3d(0.55, 2.05, 1.05), p.data(), 1, nullptr, 0, t, r);
}

VoxelIntegrationStats frame(VoxelMap* map, const std::vector<float>& depth, double t,
                            const VoxelRayConfig& r = rays()) {
  return map->integrateDepthFrustum(depth.data(), camera(), pose(), false, 1, t, r);
}

}  // namespace

TEST(VoxelFrustum, InFrontClearedBehindOutsideAndBehindCameraKept) {
  VoxelMap map(config(), 0.0, 0.0, 40, 40);
  mark(&map, 10, 20, 10, 0.0);  // centre x 1.05: 0.5 m in front of the camera, before the wall
  mark(&map, 25, 20, 10, 0.0);  // centre x 2.55: behind the wall at 2.02
  mark(&map, 10, 39, 10, 0.0);  // centre (1.05, 3.95): 75 degrees off the axis, out of the image
  mark(&map, 2, 20, 10, 0.0);   // centre x 0.25: behind the camera
  const VoxelIntegrationStats s = frame(&map, render({}, 2.02), 0.1);
  EXPECT_NEAR(map.logOdds(10, 20, 10, 0.1), kHit + kMiss, 1e-6);  // one miss: 0.442
  EXPECT_NEAR(map.logOdds(25, 20, 10, 0.1), kHit, 1e-6);
  EXPECT_NEAR(map.logOdds(10, 39, 10, 0.1), kHit, 1e-6);
  EXPECT_NEAR(map.logOdds(2, 20, 10, 0.1), kHit, 1e-6);
  // The wall's voxel (x index 20, centre 2.05 behind the surface at 2.02) is marked, not cleared,
  // and the voxel before it (centre 1.95: 0.07 m in front, within half the diagonal 0.087 m)
  // is not cleared either.
  EXPECT_NEAR(map.logOdds(20, 20, 10, 0.1), kHit, 1e-6);
  EXPECT_EQ(map.logOdds(19, 20, 10, 0.1), 0.0);
  EXPECT_NEAR(map.logOdds(18, 20, 10, 0.1), kMiss, 1e-6);  // centre 1.85: 0.17 m in front
  EXPECT_GT(s.cleared, 100u);
  EXPECT_GT(s.marked, 0u);
  EXPECT_EQ(s.rays, 41u * 41u);
  EXPECT_EQ(s.invalid_points, 0u);
}

TEST(VoxelFrustum, NoReturnPixelsClearToTheirRange) {
  VoxelMap map(config(), 0.0, 0.0, 40, 40);
  VoxelRayConfig r = rays();
  r.no_return_range_m = 1.0;
  const std::vector<float> nothing(41 * 41, kInf);
  frame(&map, nothing, 0.0, r);
  // Along the axis: centre x 1.45 is 0.9 m away (cleared), 1.65 is 1.1 m away (kept unknown).
  EXPECT_NEAR(map.logOdds(14, 20, 10, 0.0), kMiss, 1e-6);
  EXPECT_EQ(map.logOdds(16, 20, 10, 0.0), 0.0);
  // Zero is invalid unless zero_is_no_return: it clears nothing.
  VoxelMap zeros(config(), 0.0, 0.0, 40, 40);
  const std::vector<float> zero(41 * 41, 0.0f);
  const VoxelIntegrationStats s =
      zeros.integrateDepthFrustum(zero.data(), camera(), pose(), false, 1, 0.0, r);
  EXPECT_EQ(s.cleared, 0u);
  EXPECT_EQ(s.invalid_points, 41u * 41u);
  zeros.integrateDepthFrustum(zero.data(), camera(), pose(), true, 1, 0.1, r);
  EXPECT_NEAR(zeros.logOdds(14, 20, 10, 0.1), kMiss, 1e-6);
}

TEST(VoxelFrustum, ARemovedBoxIsClearedInOneFrameATableTopStays) {
  VoxelMap map(config(), 0.0, 0.0, 40, 40);
  // A box 1.22-1.4 x 1.9-2.2 x 0.9-1.2 m and a table top 1.2-1.6 x 1.6-2.5 at 0.8-0.85 m, with
  // the wall at 2.02 behind them.
  const Box box{{1.22, 1.9, 0.9}, {1.4, 2.2, 1.2}};
  const Box top{{1.2, 1.6, 0.8}, {1.6, 2.5, 0.85}};
  for (int k = 0; k < 3; ++k) frame(&map, render({box, top}, 2.02), 0.1 * k);
  const auto occupied = [&](int x, int y, int z, double t) {
    return map.state(x, y, z, t) == VoxelState::kOccupied;
  };
  EXPECT_TRUE(occupied(12, 20, 10, 0.2));  // the box's front face voxel
  EXPECT_TRUE(occupied(13, 20, 8, 0.2));   // the table top, seen from above at a grazing angle
  // The box is gone: one frame clears every box voxel the camera saw (3 hits, clamp 3.5:
  // 2.54 - 0.41 stays occupied, so compare with the log-odds one miss lower).
  const double before = map.logOdds(12, 20, 10, 0.2);
  frame(&map, render({top}, 2.02), 0.3);
  EXPECT_NEAR(map.logOdds(12, 20, 10, 0.3), before + kMiss, 1e-5);
  // The table top keeps being marked; the voxel under it (x 1.35, z 0.75) is hidden by it and
  // keeps whatever it had (never seen: unknown).
  EXPECT_TRUE(occupied(13, 20, 8, 0.3));
  EXPECT_EQ(map.logOdds(13, 20, 7, 0.3), 0.0);
  // Eight more frames without it: 3 hits - 9 misses = -1.1 < -0.3, free.
  for (int k = 4; k < 12; ++k) frame(&map, render({top}, 2.02), 0.1 * k);
  EXPECT_NEAR(map.logOdds(12, 20, 10, 1.1), 3 * kHit + 9 * kMiss, 1e-5);
  EXPECT_EQ(map.state(12, 20, 10, 1.1), VoxelState::kFree);
  EXPECT_TRUE(occupied(13, 20, 8, 1.1));
}

TEST(VoxelFrustum, BadInputIsRefused) {
  VoxelMap map(config(), 0.0, 0.0, 40, 40);
  const std::vector<float> depth(41 * 41, 1.0f);
  PinholeCamera bad = camera();
  bad.fx = std::nan("");
  EXPECT_THROW(map.integrateDepthFrustum(depth.data(), bad, pose(), false, 1, 0.0, rays()),
               std::invalid_argument);
  EXPECT_THROW(map.integrateDepthFrustum(nullptr, camera(), pose(), false, 1, 0.0, rays()),
               std::invalid_argument);
  EXPECT_THROW(map.integrateDepthFrustum(depth.data(), camera(), pose(), false, 0, 0.0, rays()),
               std::invalid_argument);
  Eigen::Isometry3d nan_pose = pose();
  nan_pose.translation().x() = std::nan("");
  EXPECT_THROW(map.integrateDepthFrustum(depth.data(), camera(), nan_pose, false, 1, 0.0, rays()),
               std::invalid_argument);
  // A camera far outside the window touches nothing and does not fail.
  Eigen::Isometry3d far = pose();
  far.translation() = Eigen::Vector3d(500.0, 500.0, 1.0);
  const VoxelIntegrationStats s =
      map.integrateDepthFrustum(depth.data(), camera(), far, false, 1, 0.0, rays());
  EXPECT_EQ(s.cleared + s.marked, 0u);
  EXPECT_EQ(map.blocks(), 0u);
}

TEST(VoxelFrustum, SaturatedFreeVoxelsAreNotRewritten) {
  // Five misses take a voxel to the clamp (-0.405 x 5 < -2). From the sixth frame of the same
  // view on, nothing in front of the wall changes: nothing is cleared or reported touched but
  // the wall's own columns. With decay on, every frame rewrites them (their stamps matter).
  VoxelMap map(config(), 0.0, 0.0, 40, 40);
  const std::vector<float> wall = render({}, 2.02);
  for (int k = 0; k < 6; ++k) frame(&map, wall, 0.1 * k);
  const VoxelIntegrationStats s = frame(&map, wall, 0.6);
  EXPECT_EQ(s.cleared, 0u);
  EXPECT_GT(s.marked, 0u);
  EXPECT_GE(s.touched.min_x, 19);  // only the wall's voxels (x index 19 .. 20)
  EXPECT_NEAR(map.logOdds(10, 20, 10, 0.6), -2.0, 1e-6);
  VoxelMapConfig decaying = config();
  decaying.decay_time_s = 100.0;
  VoxelMap fading(decaying, 0.0, 0.0, 40, 40);
  for (int k = 0; k < 6; ++k) frame(&fading, wall, 0.1 * k);
  EXPECT_GT(frame(&fading, wall, 0.6).cleared, 100u);
}
