// Free-space carving: what moved away is erased, no-return frames carve nothing, carving stays in
// the view.
#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "downstream_perception/core/tsdf/marching_cubes.h"
#include "downstream_perception/core/tsdf/occupancy_octree.h"
#include "downstream_perception/core/tsdf/tsdf_health.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

TEST(Tsdf, CarvingErasesWhatMovedAway) {
  // A wall 1.013 m ahead, seen 5 times, then gone: 10 frames see the wall behind it at 2.013 m.
  // Only the band around each depth is updated by default, so the first wall stays in the map
  // (its voxels are more than mu in front of the second); carving updates whole rays and
  // erases it. An all-"no return" frame carves up to max_depth_m.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> near_wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.013);
  const std::vector<float> far_wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 2.013);
  const auto run = [&](bool carve, std::size_t* blocks) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = carve;
    TsdfMap map(c);
    DepthIntegrator integrator;
    for (int k = 0; k < 5; ++k) {
      integrator.integrate(&map, near_wall.data(), camera, Eigen::Isometry3d::Identity());
    }
    for (int k = 0; k < 10; ++k) {
      integrator.integrate(&map, far_wall.data(), camera, Eigen::Isometry3d::Identity());
    }
    *blocks = map.blockCount();
    TsdfMesher mesher;
    mesher.update(map);
    const TriangleMesh mesh = mesher.combined();
    std::size_t near = 0, far = 0;
    for (const Eigen::Vector3f& v : mesh.vertices) {
      near += std::abs(v.z() - 1.013f) < 0.03f;
      far += std::abs(v.z() - 2.013f) < 0.03f;
    }
    return std::make_pair(near, far);
  };
  std::size_t band_blocks = 0, carved_blocks = 0;
  const auto [band_near, band_far] = run(false, &band_blocks);
  const auto [carved_near, carved_far] = run(true, &carved_blocks);
  EXPECT_GT(band_near, 100u);  // the ghost of the first wall
  EXPECT_GT(band_far, 100u);
  EXPECT_EQ(carved_near, 0u);  // erased
  EXPECT_GT(carved_far, 100u);
  EXPECT_GT(carved_blocks, band_blocks);  // the free space in front of the walls is allocated

  // No return anywhere: free along every ray up to max_depth_m, only with carving, and only
  // when the frame's returns need not be evidence (no_return_carve_min_valid_fraction 0; see
  // NoReturnFrameWithoutReturnsCarvesNothing for the default).
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.max_depth_m = 3.0;
  const std::vector<float> nothing(near_wall.size(), std::numeric_limits<float>::infinity());
  TsdfMap plain(c);
  integrateDepth(&plain, nothing.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(plain.blockCount(), 0u);
  c.carve_free_space = true;
  c.no_return_carve_min_valid_fraction = 0.0;
  TsdfMap carved(c);
  const TsdfIntegrationStats stats =
      integrateDepth(&carved, nothing.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_GT(stats.voxels_updated, 1000u);
  for (const double z : {0.5, 1.5, 2.9}) {  // on the optical axis, up to max_depth_m
    const TsdfVoxel* v = carved.voxel(carved.voxelAt({0.0, 0.0, z}));
    ASSERT_NE(v, nullptr) << z;
    EXPECT_EQ(v->distance, 1.0f) << z;
  }
  EXPECT_EQ(carved.voxel(carved.voxelAt({0.0, 0.0, 3.3})), nullptr);
}

TEST(Tsdf, NoReturnFrameWithoutReturnsCarvesNothing) {
  // Carving, ten frames of a wall 1.013 m ahead with one frame without any return (+Inf
  // everywhere: a failing sensor) in the middle. That frame carries no evidence (no valid depth):
  // its +Inf pixels are ignored and counted, and the map is bit for bit the map without it.
  // With no_return_carve_min_valid_fraction 0 the frame carves through the wall.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.013);
  const std::vector<float> nothing(wall.size(), std::numeric_limits<float>::infinity());
  const auto run = [&](bool bad_frame, double fraction, TsdfIntegrationStats* bad_stats) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = true;
    c.no_return_carve_min_valid_fraction = fraction;
    auto map = std::make_unique<TsdfMap>(c);
    DepthIntegrator integrator;
    for (int k = 0; k < 10; ++k) {
      integrator.integrate(map.get(), wall.data(), camera, Eigen::Isometry3d::Identity());
      if (bad_frame && k == 4) {
        *bad_stats =
            integrator.integrate(map.get(), nothing.data(), camera, Eigen::Isometry3d::Identity());
      }
    }
    return map;
  };
  TsdfIntegrationStats bad;
  const auto reference = run(false, 0.5, &bad);
  const auto guarded = run(true, 0.5, &bad);
  EXPECT_EQ(bad.pixels_no_return, wall.size());
  EXPECT_EQ(bad.pixels_no_return_ignored, wall.size());
  EXPECT_EQ(bad.voxels_updated, 0u);
  EXPECT_EQ(bad.blocks_allocated, 0u);
  EXPECT_EQ(guarded->blockCount(), reference->blockCount());
  EXPECT_EQ(differingVoxels(*reference, *guarded), 0u);
  const auto unguarded = run(true, 0.0, &bad);
  EXPECT_EQ(bad.pixels_no_return_ignored, 0u);
  EXPECT_GT(differingVoxels(*reference, *unguarded), 1000u);  // carved through the wall

  // Half the frame returns (the left half sees the wall), half is +Inf: at the default 0.5 the
  // returns are evidence enough, the +Inf rays carve; at 0.6 they do not.
  std::vector<float> half = wall;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = camera.width / 2; u < camera.width; ++u) {
      half[static_cast<std::size_t>(v) * camera.width + u] = std::numeric_limits<float>::infinity();
    }
  }
  const Eigen::Vector3d on_inf_ray(1.2, 0.0, 2.5);  // x/z = 0.48: the image's right half
  for (const double fraction : {0.5, 0.6}) {
    TsdfConfig c;
    c.voxel_size_m = 0.05;
    c.carve_free_space = true;
    c.no_return_carve_min_valid_fraction = fraction;
    TsdfMap map(c);
    const TsdfIntegrationStats s =
        integrateDepth(&map, half.data(), camera, Eigen::Isometry3d::Identity());
    const TsdfVoxel* v = map.voxelNear(on_inf_ray);
    if (fraction == 0.5) {
      EXPECT_EQ(s.pixels_no_return_ignored, 0u);
      ASSERT_NE(v, nullptr);
      EXPECT_EQ(v->distance, 1.0f);
    } else {
      EXPECT_EQ(s.pixels_no_return_ignored, half.size() / 2);
      EXPECT_TRUE(v == nullptr || v->weight == 0.0f);
    }
  }
  TsdfConfig bad_fraction;
  bad_fraction.no_return_carve_min_valid_fraction = 1.5;
  EXPECT_NE(bad_fraction.validate().find("no_return_carve_min_valid_fraction"), std::string::npos);
}

TEST(Tsdf, CarvedBlocksLieInTheViewFrustum) {
  // An off-axis camera (principal point an image width left of the image: every ray points
  // right), a wall and a no-return patch, carving up to max_depth_m: every allocated block
  // touches the view frustum between the camera and max_depth_m (checked on the frustum grown
  // by a block's half diagonal and mu).
  PinholeCamera camera = smallCamera();
  camera.cx = -camera.width;
  ASSERT_EQ(camera.validate(), "");
  std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.5);
  for (std::size_t i = 0; i < depth.size() / 4; ++i) {
    depth[i] = std::numeric_limits<float>::infinity();
  }
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.carve_free_space = true;
  c.max_depth_m = 3.0;
  TsdfMap map(c);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).matrix();
  T.translation() = Eigen::Vector3d(0.4, -0.2, 0.7);
  const TsdfIntegrationStats s = integrateDepth(&map, depth.data(), camera, T);
  ASSERT_GT(s.blocks_allocated, 100u);
  const double block_m = kTsdfBlockSide * c.voxel_size_m;
  const double margin = 0.5 * std::sqrt(3.0) * block_m + c.truncation();
  const double x_lo = (-0.5 - camera.cx) / camera.fx,
               x_hi = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double y_lo = (-0.5 - camera.cy) / camera.fy,
               y_hi = (camera.height - 0.5 - camera.cy) / camera.fy;
  const Eigen::Isometry3d T_camera_map = T.inverse();
  for (const auto& kv : map.blocks()) {
    const Eigen::Vector3d centre =
        T_camera_map * ((kv.first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m -
                        Eigen::Vector3d::Constant(0.5 * c.voxel_size_m));
    const double z = std::max(centre.z(), 0.0);
    ASSERT_GT(centre.z(), -margin);
    ASSERT_LT(centre.z(), c.max_depth_m + margin);
    ASSERT_GT(centre.x(), x_lo * z - margin) << kv.first.transpose();
    ASSERT_LT(centre.x(), x_hi * z + margin) << kv.first.transpose();
    ASSERT_GT(centre.y(), y_lo * z - margin);
    ASSERT_LT(centre.y(), y_hi * z + margin);
  }
}
