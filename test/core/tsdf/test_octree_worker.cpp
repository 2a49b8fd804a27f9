#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <chrono>
#include <map>
#include <thread>
#include <tuple>
#include <vector>

#include "downstream_perception/core/tsdf/octree_worker.h"
#include "tsdf_test_scenes.h"

using namespace downstream_perception;

namespace {

PinholeCamera camera() {
  return test::smallCamera();
}

/// A wall `z` metres ahead of a camera at x = `x`.
std::pair<std::vector<float>, Eigen::Isometry3d> wallFrame(double x, float z) {
  const PinholeCamera c = camera();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = x;
  return {std::vector<float>(static_cast<std::size_t>(c.width) * c.height, z), T};
}

double logOddsAt(const OccupancyOctree& tree, const Eigen::Vector3d& p) {
  double l = 0.0;
  return tree.logOdds(p, &l) ? l : -99.0;
}

/// Polls until `done` or a 10 s timeout (a hang fails the test instead of blocking it).
template <class F>
bool eventually(F done) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

struct Leaf {
  Eigen::Vector3d centre;
  float log_odds;
};
/// Every leaf of the tree by (key, depth).
using Leaves = std::map<std::tuple<int, int, int, unsigned>, Leaf>;
Leaves leavesOf(const OccupancyOctree& tree) {
  Leaves out;
  const octomap::OcTree& t = tree.tree();
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey k = it.getKey();
    out[{k[0], k[1], k[2], it.getDepth()}] = {Eigen::Vector3d(it.getX(), it.getY(), it.getZ()),
                                              it->getLogOdds()};
  }
  return out;
}

/// A tree from walls 1.5 m ahead of cameras along x from 0 to 6 m.
OccupancyOctree corridorTree(const OctreeConfig& config = {}) {
  OccupancyOctree tree(config);
  for (int k = 0; k <= 12; ++k) {
    auto [depth, T] = wallFrame(0.5 * k, 1.5f);
    tree.insertDepth(depth.data(), camera(), T);
  }
  return tree;
}

}  // namespace

TEST(OccupancyOctree, EvictFartherThanKeepsExactlyTheNearLeaves) {
  // Deleting by distance through octomap's public interface: afterwards the tree holds exactly
  // the leaves of its untouched twin whose centre lies within the radius, with their log-odds,
  // and its node count matches its structure (no stray inner node turned leaf, no miscount).
  OccupancyOctree tree = corridorTree();
  const OccupancyOctree twin = corridorTree();
  const Eigen::Vector3d centre(2.0, 0.3, 1.0);
  const double radius = 2.0;
  const Leaves all = leavesOf(twin);
  const std::size_t deleted = tree.evictFartherThan(centre, radius);
  EXPECT_GT(deleted, 100u);
  EXPECT_EQ(twin.nodeCount() - tree.nodeCount(), deleted);
  EXPECT_EQ(tree.nodeCount(), tree.tree().calcNumNodes());
  const Leaves kept = leavesOf(tree);
  std::size_t within = 0;
  for (const auto& [key, leaf] : all) {
    if ((leaf.centre - centre).norm() > radius) {
      EXPECT_EQ(kept.count(key), 0u);
      continue;
    }
    ++within;
    const auto it = kept.find(key);
    ASSERT_NE(it, kept.end());
    EXPECT_EQ(it->second.log_odds, leaf.log_odds);
  }
  EXPECT_EQ(kept.size(), within);
  EXPECT_GT(within, 100u);
  EXPECT_LT(within + 1000, all.size());
  // Everything beyond: the tree empties (its root too).
  tree.evictFartherThan(Eigen::Vector3d(100.0, 0.0, 0.0), 1.0);
  EXPECT_EQ(tree.nodeCount(), 0u);
  EXPECT_EQ(tree.leafCount(), 0u);
}

TEST(OccupancyOctree, MaintainAtTheMemoryCapKeepsTheNearestLeaves) {
  OctreeConfig config;
  config.max_memory_bytes = 0;  // no cap: the twin
  const OccupancyOctree twin = corridorTree(config);
  config.max_memory_bytes = twin.memoryBytes() / 3;
  OccupancyOctree tree = corridorTree(config);
  const Eigen::Vector3d sensor(0.0, 0.0, 0.0);
  const OctreeMaintenance m = tree.maintain(sensor);
  EXPECT_GT(m.nodes_evicted_at_cap, 0u);
  EXPECT_EQ(m.nodes_evicted_by_distance, 0u);  // max_distance_m 0: none
  EXPECT_LE(m.memory_bytes, config.max_memory_bytes);
  EXPECT_EQ(m.memory_bytes, tree.memoryBytes());
  EXPECT_EQ(m.leaves, tree.leafCount());
  EXPECT_EQ(tree.nodeCount(), tree.tree().calcNumNodes());
  // The farthest went: every leaf kept is nearer the sensor than every leaf removed.
  const Leaves all = leavesOf(twin), kept = leavesOf(tree);
  double farthest_kept = 0.0, nearest_removed = 1e9;
  for (const auto& [key, leaf] : all) {
    const double d = (leaf.centre - sensor).norm();
    if (kept.count(key) != 0) {
      farthest_kept = std::max(farthest_kept, d);
    } else {
      nearest_removed = std::min(nearest_removed, d);
    }
  }
  EXPECT_LT(farthest_kept, nearest_removed);
  EXPECT_GT(kept.size(), all.size() / 10);
  EXPECT_GT(logOddsAt(tree, Eigen::Vector3d(0.0, 0.0, 1.5)), 0.0);    // the wall nearest: kept
  EXPECT_EQ(logOddsAt(tree, Eigen::Vector3d(6.0, 0.0, 1.5)), -99.0);  // the farthest: gone
  OctreeConfig bad;
  bad.max_distance_m = -1.0;
  EXPECT_NE(bad.validate().find("max_distance_m"), std::string::npos);
  EXPECT_NE(tree.setBounds(std::nan(""), 0), "");
}

TEST(OctreeWorker, KeepsTheTreeAroundAMovingSensor) {
  // A camera moving 0.5 m per frame along a wall for 24 frames: unbounded, the OctoMap holds the
  // whole 12 m; with max_distance_m 2 (set live after 8 frames) maintenance every 4 insertions
  // keeps only what lies within 2 m of the sensor, and the stats follow it while the queue is
  // full (backlog) and after.
  OctreeWorker unbounded(OccupancyOctree{}, 64, 4);
  OctreeWorker bounded(OccupancyOctree{}, 64, 4);
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  for (int k = 0; k < 24; ++k) {
    if (k == 8) {
      bounded.waitIdle();
      EXPECT_EQ(bounded.setMaxDistance(2.0), "");
      EXPECT_NE(bounded.setMaxDistance(-1.0), "");
    }
    auto [depth, T] = wallFrame(0.5 * k, 1.5f);
    unbounded.submitDepth(depth, camera(), T);
    bounded.submitDepth(depth, camera(), T);
    last = T.translation();
  }
  unbounded.waitIdle();
  bounded.waitIdle();
  const OctreeWorker::Stats s = bounded.stats();
  EXPECT_EQ(s.inserted, 24u);
  EXPECT_EQ(s.maintenances, 6u);  // after insertions 4, 8, ..., 24
  EXPECT_GT(s.nodes_evicted_by_distance, 1000u);
  EXPECT_EQ(s.nodes_evicted_at_cap, 0u);
  bounded.read([&](const OccupancyOctree& t) {
    EXPECT_EQ(s.leaves, t.leafCount());
    EXPECT_EQ(s.memory_bytes, t.memoryBytes());
    EXPECT_EQ(s.nodes, t.nodeCount());
    for (const auto& [key, leaf] : leavesOf(t)) {
      EXPECT_LE((leaf.centre - last).norm(), 2.0);
    }
    EXPECT_GT(logOddsAt(t, last + Eigen::Vector3d(0.0, 0.0, 1.5)), 0.0);  // the wall ahead
    EXPECT_EQ(logOddsAt(t, Eigen::Vector3d(0.0, 0.0, 1.5)), -99.0);       // the first: gone
    return 0;
  });
  const std::size_t unbounded_leaves = unbounded.stats().leaves;
  EXPECT_GT(unbounded_leaves, 4 * s.leaves);
  EXPECT_EQ(unbounded.stats().nodes_evicted_by_distance, 0u);
}

TEST(OctreeWorker, AtTheMemoryCapEvictsTheFarthest) {
  // The cap is checked after every insertion (a constant-time estimate) and enforced at once.
  OctreeConfig config;
  config.max_memory_bytes = corridorTree().memoryBytes() / 4;
  OctreeWorker worker(OccupancyOctree(config), 64, 1000);  // no periodic maintenance
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  for (int k = 0; k <= 12; ++k) {
    auto [depth, T] = wallFrame(0.5 * k, 1.5f);
    worker.submitDepth(depth, camera(), T);
    last = T.translation();
  }
  worker.waitIdle();
  const OctreeWorker::Stats s = worker.stats();
  EXPECT_GT(s.maintenances, 0u);
  EXPECT_GT(s.nodes_evicted_at_cap, 0u);
  worker.read([&](const OccupancyOctree& t) {
    // Between two enforcements the tree may grow past the cap by one insertion's worth.
    EXPECT_LE(t.memoryBytes(), config.max_memory_bytes * 5 / 4);
    EXPECT_GT(logOddsAt(t, last + Eigen::Vector3d(0.0, 0.0, 1.5)), 0.0);
    EXPECT_EQ(logOddsAt(t, Eigen::Vector3d(0.0, 0.0, 1.5)), -99.0);
    return 0;
  });
}

TEST(OctreeWorker, InsertsWhatASynchronousTreeInserts) {
  OccupancyOctree direct;
  OctreeWorker worker(OccupancyOctree{}, 8);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(0.05 * i, 2.0, 0.3);
  for (int k = 0; k < 4; ++k) {
    auto [depth, T] = wallFrame(0.1 * k, 1.5f + 0.1f * static_cast<float>(k));
    direct.insertDepth(depth.data(), camera(), T);
    worker.submitDepth(depth, camera(), T);
  }
  direct.insertPoints(points, Eigen::Vector3d::Zero());
  worker.submitPoints(points, Eigen::Vector3d::Zero());
  worker.waitIdle();
  const OctreeWorker::Stats stats = worker.stats();
  EXPECT_EQ(stats.inserted, 5u);
  EXPECT_EQ(stats.dropped, 0u);
  EXPECT_EQ(stats.waiting, 0u);
  EXPECT_EQ(stats.insert_ms.count, 5u);
  ASSERT_GT(direct.leafCount(), 100u);
  EXPECT_EQ(stats.leaves, direct.leafCount());
  EXPECT_EQ(stats.memory_bytes, direct.memoryBytes());
  EXPECT_EQ(worker.read([](const OccupancyOctree& t) { return t.leafCount(); }),
            direct.leafCount());
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.0, 0.0, 1.5), Eigen::Vector3d(0.2, 0.1, 1.0),
        Eigen::Vector3d(0.5, 2.0, 0.3), Eigen::Vector3d(0.1, 0.0, 1.8)}) {
    EXPECT_EQ(worker.read([&](const OccupancyOctree& t) { return logOddsAt(t, p); }),
              logOddsAt(direct, p));
  }
  EXPECT_TRUE(worker.takeChanged());
  EXPECT_FALSE(worker.takeChanged());  // once per change
}

TEST(OctreeWorker, AFullQueuePushesOutItsOldestObservation) {
  OctreeWorker worker(OccupancyOctree{}, 1);
  auto [first, T] = wallFrame(0.0, 1.0f);
  auto [second, T2] = wallFrame(0.0, 2.0f);
  auto [third, T3] = wallFrame(0.0, 3.0f);
  // Reading holds the tree: the worker takes the first frame off the queue and then waits for
  // the tree, so the second waits in the queue and the third pushes it out.
  worker.read([&](const OccupancyOctree&) {
    worker.submitDepth(first, camera(), T);
    EXPECT_TRUE(eventually([&] { return worker.stats().waiting == 0; }));
    worker.submitDepth(second, camera(), T2);
    worker.submitDepth(third, camera(), T3);
    const OctreeWorker::Stats s = worker.stats();
    EXPECT_EQ(s.waiting, 1u);
    EXPECT_EQ(s.dropped, 1u);
    return 0;
  });
  worker.waitIdle();
  EXPECT_EQ(worker.stats().inserted, 2u);
  // Along the ray of pixel (82, 62), one of the rays the 4-pixel stride casts (from pixel 2).
  const auto on_ray = [](double z) { return Eigen::Vector3d(2.5 / 150 * z, 2.5 / 150 * z, z); };
  worker.read([&](const OccupancyOctree& t) {
    EXPECT_GT(logOddsAt(t, on_ray(1.0)), 0.0);  // first: hit, then passed once by the third
    EXPECT_LT(logOddsAt(t, on_ray(2.0)), 0.0);  // second dropped: only passed by the third
    EXPECT_GT(logOddsAt(t, on_ray(3.0)), 0.0);  // third: hit
    return 0;
  });
}

TEST(OctreeWorker, ClearEmptiesTheTreeAndDropsWhatWaits) {
  OctreeWorker worker(OccupancyOctree{}, 4);
  auto [depth, T] = wallFrame(0.0, 1.5f);
  worker.submitDepth(depth, camera(), T);
  worker.waitIdle();
  EXPECT_TRUE(worker.takeChanged());
  ASSERT_GT(worker.read([](const OccupancyOctree& t) { return t.leafCount(); }), 0u);
  worker.clear();
  EXPECT_TRUE(worker.takeChanged());
  EXPECT_EQ(worker.read([](const OccupancyOctree& t) { return t.leafCount(); }), 0u);
  EXPECT_EQ(worker.stats().leaves, 0u);
  EXPECT_THROW(OctreeWorker(OccupancyOctree{}, 0), std::invalid_argument);
}

TEST(OctreeWorker, DestructionWithObservationsWaitingReturns) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    OctreeWorker worker(OccupancyOctree{}, 16);
    for (int k = 0; k < 16; ++k) {
      auto [depth, T] = wallFrame(0.0, 1.0f + 0.1f * static_cast<float>(k));
      worker.submitDepth(depth, camera(), T);
    }
  }  // finishes at most the insertion under way; the waiting ones are dropped
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}
