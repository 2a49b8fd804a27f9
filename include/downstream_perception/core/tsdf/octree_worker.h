// Inserts observations into an OccupancyOctree on a thread of its own. OctoMap's ray casting
// takes tens of milliseconds per depth frame (about 35 ms for 320 x 240 at 5 cm leaves and a
// 4-pixel stride), several times the TSDF's integration: done in the sensor callback it would
// hold up the TSDF and make the node drop frames.
#pragma once

#include <Eigen/Geometry>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tsdf/occupancy_octree.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace downstream_perception {

/// Observations wait in a queue of at most `queue_size`; a new one arriving at a full queue
/// pushes out the oldest waiting one (counted as dropped), so the OctoMap lags the TSDF by at
/// most that many observations and never builds up a backlog.
///
/// The worker also keeps the tree within its memory bounds (OctreeConfig::max_distance_m,
/// max_memory_bytes): OccupancyOctree::maintain() around the latest sensor origin every
/// `maintenance_every` insertions, and at once when the tree's node count suggests it reached
/// the memory cap (a constant-time estimate checked after each insertion).
class OctreeWorker {
 public:
  struct Stats {
    std::size_t inserted = 0;
    std::size_t dropped = 0;  ///< pushed out of a full queue, never inserted
    std::size_t waiting = 0;
    RunningStats insert_ms;
    /// The tree's size after the last maintenance, after the last insertion that left no
    /// observation waiting, or after a clearing (counting walks the tree, so the worker does
    /// it, not the caller). Maintenance runs every maintenance_every insertions, so these stay
    /// current while observations keep coming.
    std::size_t leaves = 0;
    std::size_t memory_bytes = 0;
    std::size_t nodes = 0;  ///< after the last insertion (constant time)
    std::size_t maintenances = 0;
    RunningStats maintenance_ms;
    std::size_t nodes_evicted_by_distance = 0;  ///< total over the worker's life
    std::size_t nodes_evicted_at_cap = 0;       ///< total: the farthest, at max_memory_bytes
  };

  /// Throws std::invalid_argument for queue_size 0 or maintenance_every 0.
  OctreeWorker(OccupancyOctree tree, std::size_t queue_size, std::size_t maintenance_every = 10);
  /// Finishes the insertion under way, drops the waiting ones.
  ~OctreeWorker();
  OctreeWorker(const OctreeWorker&) = delete;
  OctreeWorker& operator=(const OctreeWorker&) = delete;

  /// A depth image (metres, as integrateDepth) and the camera's pose in the map frame.
  void submitDepth(std::vector<float> depth, const PinholeCamera& camera,
                   const Eigen::Isometry3d& T_map_camera);
  /// Points in the map frame, seen from `origin` (map frame).
  void submitPoints(std::vector<Eigen::Vector3d> points, const Eigen::Vector3d& origin);

  /// Calls f(const OccupancyOctree&) between insertions and returns its result.
  template <class F>
  auto read(F&& f) const {
    std::lock_guard<std::mutex> lock(tree_mutex_);
    return f(tree_);
  }
  /// Empties the tree and drops the waiting observations (they predate the clearing).
  void clear();
  /// A new OctreeConfig::max_distance_m (the TSDF's max_block_distance_m changed live), applied
  /// from the next insertion on. Empty on success, else the reason and nothing changes.
  std::string setMaxDistance(double max_distance_m);
  /// True once per change: whether an insertion or a clearing happened since the last call.
  bool takeChanged();
  /// Returns when nothing waits and no insertion runs.
  void waitIdle();
  Stats stats() const;

 private:
  struct Observation {
    std::vector<float> depth;  ///< empty for points
    PinholeCamera camera;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< T_map_camera, or the origin
    std::vector<Eigen::Vector3d> points;
  };
  void push(Observation observation);
  void run();
  /// Inserts `o` and keeps the bounds; runs on the worker thread, under tree_mutex_.
  void insert(const Observation& o, bool backlog);

  const std::size_t queue_size_;
  const std::size_t maintenance_every_;
  mutable std::mutex tree_mutex_;  ///< guards tree_ and the worker thread's state below
  OccupancyOctree tree_;
  std::size_t since_maintenance_ = 0;
  /// memoryBytes() / nodeCount() at the last count; starts at the worst case (every node an
  /// inner node with its 8-pointer child array), so the first estimate errs high.
  double bytes_per_node_ = 80.0;
  OctreeMaintenance last_maintenance_;
  double last_maintenance_ms_ = 0.0;
  bool maintained_ = false;         ///< by the last insert()
  bool counted_ = false;            ///< leaves and memory counted by the last insert()
  mutable std::mutex queue_mutex_;  ///< guards everything below
  std::condition_variable wake_;    ///< an observation arrived, or stop
  std::condition_variable idle_;    ///< the queue ran empty and no insertion runs
  std::deque<Observation> queue_;
  bool busy_ = false;
  bool stop_ = false;
  bool changed_ = false;
  std::optional<double> pending_max_distance_m_;
  Stats stats_;
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace downstream_perception
