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
  double resolution_m = 0.05;
  double prob_hit = 0.7;   ///< log-odds +0.847 per hit
  double prob_miss = 0.4;  ///< log-odds -0.405 per pass
  double max_range_m = 10.0;
  int depth_stride_px = 4;  ///< depth images: every n-th pixel in each direction is a ray
  std::string validate() const;
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
