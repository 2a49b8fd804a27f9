// OctoMap occupancy from the same observations as the TSDF: an octomap::OcTree (log-odds per
// leaf, the lesson's +0.847 / -0.405 for p_hit 0.7 / p_miss 0.4) filled by ray casting from the
// sensor, saved as .bt, its occupied leaves listed for rviz. OctoMap is the 3-D occupancy map
// users compare against; it answers "occupied?" where the TSDF answers "how far?".
#pragma once

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace octomap {
class OcTree;
}

namespace downstream_perception {

struct OctreeConfig {
  double resolution_m = 0.05;  ///< leaf size, m
  double prob_hit = 0.7;       ///< log-odds +0.847 per hit
  double prob_miss = 0.4;      ///< log-odds -0.405 per pass
  double max_range_m = 10.0;   ///< rays are cut at this range, m
  int depth_stride_px = 4;     ///< depth images: every n-th pixel in each direction is a ray
  /// Memory bounds, the OctoMap's counterparts of the TSDF's (applied by maintain()):
  /// leaves farther than this from the sensor are deleted (0 = never; the TSDF node passes its
  /// max_block_distance_m); rays are also cut at this range (what lies beyond would go at the
  /// next maintenance anyway).
  double max_distance_m = 0.0;
  /// Cap on memoryBytes() (octomap's count: nodes and child arrays; the heap adds the
  /// allocator's overhead, about a third more). At the cap maintain() deletes the leaves
  /// farthest from the sensor until the tree is below 90 % of it (0 = no cap).
  std::size_t max_memory_bytes = std::size_t{256} << 20;
  std::string validate() const;
};

/// What one OccupancyOctree::maintain() did, and the tree's size after it.
struct OctreeMaintenance {
  std::size_t nodes_evicted_by_distance = 0;  ///< nodes (leaves and inner) deleted
  std::size_t nodes_evicted_at_cap = 0;
  std::size_t leaves = 0;
  std::size_t memory_bytes = 0;
};

class OccupancyOctree {
 public:
  /// Throws std::invalid_argument if the config is invalid.
  explicit OccupancyOctree(const OctreeConfig& config = {});
  ~OccupancyOctree();
  OccupancyOctree(OccupancyOctree&&) noexcept;
  OccupancyOctree& operator=(OccupancyOctree&&) noexcept;

  /// Rays from `origin` (map frame) to each finite point: leaves passed get a miss, the end
  /// leaf a hit (octomap's insertPointCloud, each leaf updated once per call).
  void insertPoints(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& origin);
  /// A depth image (metres; as integrateDepth) sub-sampled by depth_stride_px.
  void insertDepth(const float* depth, const PinholeCamera& camera,
                   const Eigen::Isometry3d& T_map_camera);

  /// Deletes every leaf whose centre is farther than `distance_m` from `center` (whole subtrees
  /// at once where they lie entirely beyond it), and the inner nodes left without children;
  /// the inner nodes on the way keep the maximum of their remaining children. Returns the
  /// number of nodes deleted.
  std::size_t evictFartherThan(const Eigen::Vector3d& center, double distance_m);
  /// Bounds the tree around the sensor at `sensor_origin` (map frame): max_distance_m eviction,
  /// octomap's prune() (merges 8 equal leaves into their parent), then the max_memory_bytes cap
  /// (the farthest leaves go first). Walks the tree: tens of ms for a million nodes.
  OctreeMaintenance maintain(const Eigen::Vector3d& sensor_origin);
  /// Replaces the memory bounds (max_distance_m, max_memory_bytes; checked as validate()).
  /// Empty on success, else the reason and nothing changes.
  std::string setBounds(double max_distance_m, std::size_t max_memory_bytes);
  /// Nodes in the tree (inner and leaves); constant time, unlike leafCount() and memoryBytes().
  std::size_t nodeCount() const;
  /// The octomap tree itself, read-only (tests check its structure).
  const octomap::OcTree& tree() const { return *tree_; }

  /// Log-odds of the leaf containing p, if it was observed.
  bool logOdds(const Eigen::Vector3d& p, double* log_odds) const;
  /// Centres of the occupied leaves (at full resolution).
  std::vector<Eigen::Vector3d> occupiedCenters() const;
  std::size_t leafCount() const;
  std::size_t memoryBytes() const;
  /// Binary .bt (maximum-likelihood occupancy). Empty string or the reason.
  std::string writeBinary(const std::string& path) const;
  /// The same .bt into a stream (a service writes it through an OutputDirectory).
  bool writeBinary(std::ostream& out) const;
  void clear();
  const OctreeConfig& config() const { return config_; }

 private:
  OctreeConfig config_;
  std::unique_ptr<octomap::OcTree> tree_;
};

}  // namespace downstream_perception
