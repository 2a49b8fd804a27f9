// The ESDF against a brute-force exact oracle (full and incremental, two lattice offsets, a
// removed object, evicted blocks), and its interpolated distance and gradient on a plane and a
// sphere, with the expected numbers derived by hand.
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "downstream_perception/core/tsdf/distance_transform_3d.h"
#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "esdf_test_helpers.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

// Radii on both sides of the transform's switches from the brute-force window to the lower
// envelope (32-bit results: window up to r = 64; 16-bit results: window only, up to 127, a larger
// radius refused), on boxes longer than 2 r + 1 along some axis, with seeds sparse enough that
// planes and rows without any are skipped.
struct TransformCase {
  Eigen::Vector3i size;
  int radius;
  int seed_one_in;
};

class DistanceTransform3dRadii : public ::testing::TestWithParam<TransformCase> {};

TEST_P(DistanceTransform3dRadii, MatchesBruteForceOnRandomSeeds) {
  const Eigen::Vector3i size = GetParam().size;
  const int radius = GetParam().radius;
  std::mt19937 rng(7 + radius);
  std::vector<std::uint8_t> labels(static_cast<std::size_t>(size.prod()));
  for (auto& l : labels) {
    l = static_cast<std::uint8_t>(rng() % GetParam().seed_one_in == 0 ? 2 : rng() % 3 == 0);
  }
  std::vector<std::int32_t> out;
  std::vector<std::int16_t> out16;
  EdtScratch scratch;
  boundedSquaredDistances3d(labels.data(), size, 2, radius, &out, &scratch);
  ASSERT_EQ(out.size(), labels.size());
  const bool narrow = radius <= kEdtMaxRadius16;
  if (narrow) {
    boundedSquaredDistances3d(labels.data(), size, 2, radius, &out16, &scratch);
    ASSERT_EQ(out16.size(), labels.size());
  } else {
    EXPECT_THROW(boundedSquaredDistances3d(labels.data(), size, 2, radius, &out16, &scratch),
                 std::invalid_argument);
  }
  std::vector<Eigen::Vector3i> seeds;
  for (int k = 0; k < size.prod(); ++k) {
    if (labels[k] == 2) {
      seeds.emplace_back(k % size.x(), k / size.x() % size.y(), k / (size.x() * size.y()));
    }
  }
  std::size_t off = 0, within = 0, far = 0;
  for (int z = 0; z < size.z(); ++z) {
    for (int y = 0; y < size.y(); ++y) {
      for (int x = 0; x < size.x(); ++x) {
        std::int32_t best = kEdtFarSquared;
        for (const Eigen::Vector3i& s : seeds) {
          const int d2 = (s - Eigen::Vector3i(x, y, z)).squaredNorm();
          if (d2 <= radius * radius) best = std::min(best, d2);
        }
        const int i = (z * size.y() + y) * size.x() + x;
        off += out[i] != best;
        if (narrow) off += out16[i] != (best == kEdtFarSquared ? kEdtFarSquared16 : best);
        within += best != kEdtFarSquared && best > 0;
        far += best == kEdtFarSquared;
      }
    }
  }
  EXPECT_EQ(off, 0u);
  // The test sees real distances, not only seeds and "far" (none within radius 0), and, with
  // sparse seeds, voxels out of reach.
  if (radius > 0) EXPECT_GT(within, 1000u);
  if (radius == 0) EXPECT_EQ(within, 0u);
  if (GetParam().seed_one_in > 100) EXPECT_GT(far, 500u);
}

INSTANTIATE_TEST_SUITE_P(
    WindowAndEnvelope, DistanceTransform3dRadii,
    ::testing::Values(TransformCase{{23, 17, 13}, 6, 50},     // window, dense seeds
                      TransformCase{{181, 9, 11}, 40, 8000},  // window, sparse seeds
                      TransformCase{{181, 9, 11}, 64, 8000},  // 32-bit window at its largest
                      TransformCase{{181, 9, 11}, 65, 8000},  // 32-bit envelope
                      TransformCase{{401, 5, 5}, 127, 8000},  // 16-bit window at its largest
                      TransformCase{{401, 5, 5}, 128, 8000},  // envelope only
                      TransformCase{{9, 11, 83}, 5, 300},     // window, sparse: rows skipped
                      TransformCase{{23, 17, 13}, 0, 50}));   // radius 0: seeds only

class EsdfRoomOffsets : public ::testing::TestWithParam<Eigen::Vector3d> {};

TEST_P(EsdfRoomOffsets, FullComputationMatchesTheOracle) {
  RoomScene scene;
  scene.offset = GetParam();
  const TsdfMap map = filledRoom(0.1, scene);
  EsdfConfig c;
  c.max_distance_m = 0.5;
  Esdf esdf(c, 0.1);
  const EsdfUpdateStats stats = esdf.update(map);
  EXPECT_TRUE(stats.full);
  EXPECT_EQ(esdf.blockCount(), map.blockCount());
  const OracleComparison o = compareWithOracle(map, esdf);
  EXPECT_EQ(o.off, 0u);
  EXPECT_GT(o.in_band, 20000u);
  EXPECT_GT(o.occupied, 5000u);
  EXPECT_GT(o.known - o.in_band, 1000u);  // clamped voxels too
}

INSTANTIATE_TEST_SUITE_P(Lattice, EsdfRoomOffsets,
                         ::testing::Values(Eigen::Vector3d::Zero(),
                                           Eigen::Vector3d(0.037, 0.061, 0.023)));

TEST(Esdf, IncrementalUpdatesOfARealSequenceMatchTheOracle) {
  // The depth camera circles the room with free-space carving; after frames, the box is taken
  // away and its space carved free again. Every update is incremental and exact.
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0.0073, -0.0041, 0.0029), Eigen::Vector3d(0.05, 0.05, 0.05)}) {
    RoomScene scene;
    scene.offset = offset;
    TsdfConfig tc;
    tc.voxel_size_m = 0.1;
    tc.carve_free_space = true;
    TsdfMap map(tc);
    EsdfConfig c;
    c.max_distance_m = 0.6;
    Esdf esdf(c, tc.voxel_size_m);
    DepthIntegrator integrator;
    const PinholeCamera camera = smallCamera();
    constexpr int kFrames = 12;
    std::size_t changed_after_removal = 0;
    for (int i = 0; i < 2 * kFrames; ++i) {
      scene.with_box = i < kFrames;
      const Eigen::Isometry3d pose = circlePose(i % kFrames, kFrames);
      integrator.integrate(&map, renderDepth(camera, pose, scene).data(), camera, pose);
      const EsdfUpdateStats stats = esdf.update(map);
      EXPECT_EQ(stats.full, i == 0);
      if (i >= kFrames) changed_after_removal += stats.voxels_changed;
      if (i == 3 || i == kFrames - 1 || i == 2 * kFrames - 1) {
        const OracleComparison o = compareWithOracle(map, esdf);
        EXPECT_EQ(o.off, 0u) << "frame " << i;
        EXPECT_GT(o.in_band, 5000u);
        EXPECT_GT(o.occupied, 500u);
      }
    }
    EXPECT_GT(changed_after_removal, 100u);
    // The box's place is free now: its centre reads a positive distance (it was inside).
    const Eigen::Vector3d box_centre = Eigen::Vector3d(0.8, 0.6, 0.35) + offset;
    EXPECT_GT(esdf.voxelDistance(map.voxelAt(box_centre)), 0.0f);
  }
}

TEST(Esdf, AChangeIsRecomputedOnlyWithinReach) {
  // A 6.4 x 6.4 m floor at 10 cm (max distance 0.5 m: 6 voxels, so a change reaches one
  // block further); then a small post appears in one block. Only the blocks within reach of that
  // block are recomputed, from a region of them plus one block of seeds, and the field is exact.
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  const auto floor = [&](const Eigen::Vector3d& p) {
    return std::clamp((p.z() - 0.037) / mu, -1.0, 1.0);
  };
  fill(&map, {-32, -32, -8}, {31, 31, 15}, floor);
  EsdfConfig c;
  c.max_distance_m = 0.5;
  Esdf esdf(c, 0.1);
  EXPECT_TRUE(esdf.update(map).full);
  EXPECT_EQ(esdf.update(map).blocks_written, 0u);  // nothing integrated: nothing recomputed
  // The post: voxels (2..3, 2..3, 1..5) become occupied; only their block is stamped.
  const std::uint64_t generation = map.beginIntegration();
  for (int z = 1; z <= 5; ++z) {
    for (int y = 2; y <= 3; ++y) {
      for (int x = 2; x <= 3; ++x) {
        const Eigen::Vector3i v(x, y, z);
        map.find(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)].distance = -0.1f;
      }
    }
  }
  map.find({0, 0, 0})->updated_stamp = generation;
  const EsdfUpdateStats stats = esdf.update(map);
  EXPECT_FALSE(stats.full);
  EXPECT_EQ(stats.blocks_read, 1u);
  EXPECT_EQ(stats.voxels_changed, 20u);
  // Blocks within one block of block (0, 0, 0) that exist: 3 x 3 x 3 (z blocks -1..1 exist).
  EXPECT_EQ(stats.blocks_written, 27u);
  EXPECT_EQ(stats.region_voxels, std::size_t{5 * 5 * 3} * kTsdfBlockVoxels);  // + 1 block of seeds
  EXPECT_EQ(compareWithOracle(map, esdf).off, 0u);
  // One voxel above the post's top voxel (z index 5): (1 - 1/2) * 0.1 m; two voxels beside it
  // (x index 5): (2 - 1/2) * 0.1 m (the floor is 3 voxels below).
  EXPECT_FLOAT_EQ(esdf.voxelDistance({2, 2, 6}), 0.05f);
  EXPECT_FLOAT_EQ(esdf.voxelDistance({5, 2, 3}), 0.15f);
}

TEST(Esdf, ScatteredChangesAreRecomputedAsSeparateRegions) {
  // Two floor patches 200 blocks apart (160 m at 10 cm), then a post appears on each: the blocks
  // within reach of the two are found without dense marks (200^3 blocks), each post's
  // neighbourhood is its own region, and both match the oracle.
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  const Eigen::Vector3i far_block(200, 200, 200);
  const Eigen::Vector3i far = far_block * kTsdfBlockSide;
  for (const Eigen::Vector3i& o : {Eigen::Vector3i::Zero().eval(), far}) {
    const double floor_z = (o.z() + 0.37) * 0.1;
    fill(&map, o + Eigen::Vector3i(-16, -16, -8), o + Eigen::Vector3i(15, 15, 15),
         [&](const Eigen::Vector3d& p) { return std::clamp((p.z() - floor_z) / mu, -1.0, 1.0); });
  }
  EsdfConfig c;
  c.max_distance_m = 0.5;
  Esdf esdf(c, 0.1);
  EXPECT_TRUE(esdf.update(map).full);
  const std::uint64_t generation = map.beginIntegration();
  for (const Eigen::Vector3i& o : {Eigen::Vector3i::Zero().eval(), far}) {
    for (int z = 1; z <= 5; ++z) {
      const Eigen::Vector3i v = o + Eigen::Vector3i(2, 2, z);
      map.find(TsdfMap::blockOf(v))->voxels[TsdfMap::localIndex(v)].distance = -0.1f;
    }
    map.find(TsdfMap::blockOf(o))->updated_stamp = generation;
  }
  const EsdfUpdateStats stats = esdf.update(map);
  EXPECT_FALSE(stats.full);
  EXPECT_EQ(stats.voxels_changed, 10u);
  EXPECT_EQ(stats.blocks_written, 54u);  // 27 around each post
  EXPECT_EQ(stats.regions, 2u);
  for (const Eigen::Vector3i& b : {Eigen::Vector3i::Zero().eval(), far_block}) {
    const OracleComparison o = compareWithOracle(map, esdf, &b);
    EXPECT_EQ(o.off, 0u);
    EXPECT_GT(o.known, 20000u);
  }
  // Beside each post, two voxels away: (2 - 1/2) * 0.1 m.
  EXPECT_FLOAT_EQ(esdf.voxelDistance({4, 2, 3}), 0.15f);
  EXPECT_FLOAT_EQ(esdf.voxelDistance(far + Eigen::Vector3i(4, 2, 3)), 0.15f);
}

TEST(Esdf, EvictedAndClearedBlocksLeaveTheField) {
  TsdfMap map = filledRoom(0.1, RoomScene{});
  EsdfConfig c;
  c.max_distance_m = 0.5;
  Esdf esdf(c, 0.1);
  esdf.update(map);
  const std::size_t before = esdf.blockCount();
  const std::size_t evicted = map.evictFartherThan({2.0, 2.0, 1.5}, 2.5);
  ASSERT_GT(evicted, 0u);
  const EsdfUpdateStats stats = esdf.update(map);
  EXPECT_FALSE(stats.full);
  EXPECT_EQ(stats.blocks_removed, evicted);
  EXPECT_EQ(esdf.blockCount(), before - evicted);
  EXPECT_EQ(compareWithOracle(map, esdf).off, 0u);
  EXPECT_LE(esdf.memoryBytes(),
            esdf.blockCount() * sizeof(EsdfBlock) * 2 + (std::size_t{64} << 20));
  map.clear();
  esdf.update(map);
  EXPECT_EQ(esdf.blockCount(), 0u);
}

TEST(Esdf, AClearedMapIntegratedAgainElsewhereUpdatesIncrementally) {
  // Found by the fuzz campaign: after a clear, the dropped blocks are changes, and those beyond
  // the new blocks' extent along x only (same y and z) made the reach marking fill a row from
  // past its end (a crash or heap damage). Now they are skipped, and the field is exact.
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  const auto slab = [&](const Eigen::Vector3d& p) {
    return std::clamp((p.z() - 0.237) / mu, -1.0, 1.0);
  };
  fill(&map, {0, 0, -3}, {15, 15, 12}, slab);  // blocks x, y 0..1
  Esdf esdf(EsdfConfig{}, 0.1);                // 1 m: a reach of 2 blocks
  EXPECT_TRUE(esdf.update(map).full);
  map.clear();
  fill(&map, {64, 0, -3}, {79, 15, 12}, slab);  // blocks x 8..9: 6 blocks beyond the reach
  const EsdfUpdateStats stats = esdf.update(map);
  EXPECT_FALSE(stats.full);
  EXPECT_GT(stats.blocks_removed, 0u);
  EXPECT_EQ(esdf.blockCount(), map.blockCount());
  const OracleComparison o = compareWithOracle(map, esdf);
  EXPECT_EQ(o.off, 0u);
  EXPECT_GT(o.known, 4000u);
}

TEST(Esdf, PlaneDistanceAndGradientAreExact) {
  // Floor plane z = 0.237 m at 10 cm voxels: voxels k <= 2 are occupied (centres below it), the
  // first free layer is k = 3. A free voxel k is k - 2 voxels above the nearest occupied one:
  // (k - 2 - 1/2) * 0.1 = z - 0.25 m; an occupied one -(3 - k - 1/2) * 0.1, the same line. So
  // the interpolated field is d(p) = p.z - 0.25 with gradient (0, 0, 1), anywhere in between.
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  fill(&map, {-10, -10, -3}, {10, 10, 12},
       [&](const Eigen::Vector3d& p) { return std::clamp((p.z() - 0.237) / mu, -1.0, 1.0); });
  Esdf esdf(EsdfConfig{}, 0.1);  // max 1 m
  esdf.update(map);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.013, -0.321, 0.53), Eigen::Vector3d(0.5, 0.5, 0.26),
        Eigen::Vector3d(-0.2, 0.1, 0.18), Eigen::Vector3d(0.33, 0.44, 1.01)}) {
    const EsdfSample s = esdf.sample(p);
    ASSERT_TRUE(s.observed);
    EXPECT_NEAR(s.distance, p.z() - 0.25, 1e-6) << p.transpose();
    EXPECT_NEAR((s.gradient - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-5) << p.transpose();
  }
  // Beyond the observed block the field is unknown, not zero.
  const EsdfSample outside = esdf.sample({5.0, 0.0, 0.5});
  EXPECT_FALSE(outside.observed);
  EXPECT_TRUE(std::isnan(outside.distance));
}

TEST(Esdf, SphereDistanceAndGradient) {
  // Solid sphere of radius 0.52 m centred on a voxel centre, 10 cm voxels. Occupied voxels have
  // |v| < 5.2 voxels: (5, 0, 0), (5, 1, 0), (5, 1, 1) (|v|^2 = 25, 26, 27 < 27.04), none with
  // x >= 6 (36 > 27.04). So every voxel (k, y, z) with k >= 6, |y|, |z| <= 1 is exactly k - 5
  // voxels from the nearest occupied one: d = (k - 5.5) * 0.1 m. Between x = 8 and 9 voxels the
  // interpolated field is d = x - 0.55 m with gradient (1, 0, 0), for any y, z in [0, 1] voxels.
  TsdfConfig tc;
  tc.voxel_size_m = 0.1;
  TsdfMap map(tc);
  const double mu = tc.truncation();
  const Eigen::Vector3d centre(0.3, -0.2, 1.0);
  fill(&map, {-14, -18, -4}, {20, 16, 24}, [&](const Eigen::Vector3d& p) {
    return std::clamp(((p - centre).norm() - 0.52) / mu, -1.0, 1.0);
  });
  EsdfConfig c;
  c.max_distance_m = 1.0;
  Esdf esdf(c, 0.1);
  esdf.update(map);
  const EsdfSample s = esdf.sample(centre + Eigen::Vector3d(0.83, 0.04, 0.07));
  ASSERT_TRUE(s.observed);
  EXPECT_NEAR(s.distance, 0.28, 1e-6);
  EXPECT_NEAR((s.gradient - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-5);
  // Elsewhere around the sphere: the distance within a voxel of |p - c| - r and the gradient
  // within 20 degrees of radial (the staircase of a 0.52 m sphere on a 10 cm lattice turns it by up
  // to 18 degrees over these 200 directions), |gradient| within 20 % of 1.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d dir = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double r = 0.75 + 0.2 * (i % 5) / 4.0;
    const EsdfSample q = esdf.sample(centre + r * dir);
    ASSERT_TRUE(q.observed);
    EXPECT_NEAR(q.distance, r - 0.52, 0.1);
    EXPECT_GT(q.gradient.normalized().dot(dir), std::cos(20.0 * M_PI / 180.0));
    EXPECT_NEAR(q.gradient.norm(), 1.0, 0.2);
  }
}

TEST(Esdf, ConfigIsValidated) {
  EsdfConfig c;
  EXPECT_EQ(c.validate(0.05), "");
  c.max_distance_m = 0.01;  // below a voxel
  EXPECT_NE(c.validate(0.05), "");
  c.max_distance_m = 100.0;  // beyond kMaxDistanceVoxels
  EXPECT_NE(c.validate(0.05), "");
  c.max_distance_m = std::nan("");
  EXPECT_THROW(Esdf(c, 0.05), std::invalid_argument);
  Esdf esdf(EsdfConfig{}, 0.05);
  TsdfMap other;  // 2 cm voxels
  EXPECT_THROW(esdf.update(other), std::invalid_argument);
}
