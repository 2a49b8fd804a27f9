#include <gtest/gtest.h>

#include <chrono>
#include <thread>
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

}  // namespace

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
