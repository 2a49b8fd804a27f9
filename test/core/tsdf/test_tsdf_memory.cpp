// Memory bounds: the block pool, max_blocks and the distance eviction.
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

TEST(Tsdf, MemoryIsBoundedByMaxBlocksAndDistance) {
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  c.max_blocks = 10;
  TsdfMap capped(c);
  const PinholeCamera camera = smallCamera();
  const std::vector<float> depth = planeDepth(camera, Eigen::Vector3d::UnitZ(), 2.0);
  const TsdfIntegrationStats s =
      integrateDepth(&capped, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_EQ(capped.blockCount(), 10u);
  EXPECT_GT(s.blocks_refused, 0u);
  EXPECT_GT(capped.memoryBytes(), 10 * sizeof(TsdfBlock) - 1);

  c.max_blocks = 100000;
  c.max_block_distance_m = 1.0;  // the plane at 2 m is beyond: all evicted
  TsdfMap near(c);
  const TsdfIntegrationStats e =
      integrateDepth(&near, depth.data(), camera, Eigen::Isometry3d::Identity());
  EXPECT_GT(e.blocks_evicted, 0u);
  EXPECT_EQ(near.blockCount(), 0u);
  // Evicted blocks' memory stays for reuse (the pool keeps its peak); clear() returns it.
  EXPECT_GE(near.memoryBytes(), TsdfBlockPool::kChunkBytes);
  capped.clear();
  EXPECT_LT(capped.memoryBytes(), TsdfBlockPool::kChunkBytes);
}

TEST(TsdfBlockPool, ReusesReleasedBlocksZeroedAndFreesChunksWhenEmpty) {
  TsdfBlockPool pool;
  const std::size_t per_chunk = TsdfBlockPool::blocksPerChunk();
  EXPECT_GE(per_chunk, 500u);  // 2 MiB of 4,104-byte blocks
  std::vector<TsdfBlockPool::Ptr> blocks;
  for (std::size_t i = 0; i < per_chunk + 3; ++i) {
    blocks.push_back(pool.acquire());
    blocks.back()->voxels[7].distance = static_cast<float>(i);
    blocks.back()->voxels[kTsdfBlockVoxels - 1].weight = 1.0f;
    blocks.back()->updated_stamp = i + 1;
  }
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  EXPECT_EQ(pool.blocksInUse(), per_chunk + 3);
  for (std::size_t i = 0; i < blocks.size(); ++i) {  // no block overlaps another
    ASSERT_EQ(blocks[i]->voxels[7].distance, static_cast<float>(i));
    ASSERT_EQ(blocks[i]->updated_stamp, i + 1);
  }
  for (std::size_t i = 0; i < blocks.size(); i += 2) blocks[i].reset();
  pool.trim();  // blocks in use: nothing to give back
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  for (std::size_t i = 0; i < blocks.size(); i += 2) {
    blocks[i] = pool.acquire();  // a reused slot, zeroed
    EXPECT_EQ(blocks[i]->voxels[7].distance, 0.0f);
    EXPECT_EQ(blocks[i]->voxels[kTsdfBlockVoxels - 1].weight, 0.0f);
    EXPECT_EQ(blocks[i]->updated_stamp, 0u);
  }
  EXPECT_EQ(pool.bytesReserved(), 2 * TsdfBlockPool::kChunkBytes);
  blocks.clear();
  EXPECT_EQ(pool.blocksInUse(), 0u);
  pool.trim();
  EXPECT_EQ(pool.bytesReserved(), 0u);
}

TEST(Tsdf, LoweringMaxBlocksLiveEvictsTheLeastRecentlyUpdatedFirst) {
  // Two walls seen from cameras 5 m apart, the second later: lowering max_blocks to the number
  // of blocks the second frame updated evicts all others (the first frame's, and blocks
  // allocated but never updated); lowering it further evicts, among the equally recent blocks,
  // the farthest from the last camera.
  const PinholeCamera camera = smallCamera();
  const std::vector<float> wall = planeDepth(camera, Eigen::Vector3d::UnitZ(), 1.0);
  TsdfConfig c;
  c.voxel_size_m = 0.05;
  TsdfMap map(c);
  Eigen::Isometry3d first = Eigen::Isometry3d::Identity(), second = first;
  second.translation().x() = 5.0;
  integrateDepth(&map, wall.data(), camera, first);
  const std::size_t first_count = map.blockCount();
  integrateDepth(&map, wall.data(), camera, second);
  const std::size_t total = map.blockCount();
  std::size_t second_count = 0;
  for (const auto& kv : map.blocks()) second_count += kv.second->updated_stamp == map.generation();
  ASSERT_GT(first_count, 10u);
  ASSERT_GT(second_count, 10u);
  ASSERT_LT(second_count, total - first_count + 1);
  TsdfConfig lower = c;
  lower.max_blocks = second_count;
  ASSERT_EQ(map.setConfig(lower), "");
  EXPECT_EQ(map.blockCount(), second_count);
  EXPECT_EQ(map.blocksEvictedToCap(), total - second_count);
  for (const auto& kv : map.blocks()) EXPECT_EQ(kv.second->updated_stamp, map.generation());
  const auto distances = [&map](const TsdfMap& m) {
    std::vector<double> d;
    const double block_m = kTsdfBlockSide * m.voxelSize();
    for (const auto& kv : m.blocks()) {
      d.push_back(((kv.first.cast<double>() + Eigen::Vector3d::Constant(0.5)) * block_m -
                   map.sensorOrigin())
                      .norm());
    }
    return d;
  };
  const std::vector<double> before = distances(map);
  lower.max_blocks = second_count / 2;
  ASSERT_EQ(map.setConfig(lower), "");
  EXPECT_EQ(map.blockCount(), second_count / 2);
  EXPECT_EQ(map.blocksEvictedToCap(), total - second_count / 2);
  const std::vector<double> after = distances(map);
  std::vector<double> sorted = before;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_LE(*std::max_element(after.begin(), after.end()), sorted[after.size() - 1]);
  // The cap holds from then on: a new frame allocates nothing beyond it.
  const TsdfIntegrationStats s = integrateDepth(&map, wall.data(), camera, first);
  EXPECT_EQ(map.blockCount(), second_count / 2);
  EXPECT_GT(s.blocks_refused, 0u);
}
