#include "downstream_perception/core/tsdf/occupancy_octree.h"

#include <octomap/OcTree.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

std::string OctreeConfig::validate() const {
  std::ostringstream why;
  if (!(std::isfinite(resolution_m) && resolution_m >= 0.001 && resolution_m <= 10.0)) {
    why << "resolution_m must be in [0.001, 10] m, got " << resolution_m;
  } else if (!(prob_hit > 0.5 && prob_hit < 1.0 && prob_miss > 0.0 && prob_miss < 0.5)) {
    why << "need 0.5 < prob_hit < 1 and 0 < prob_miss < 0.5, got " << prob_hit << " and "
        << prob_miss;
  } else if (!(std::isfinite(max_range_m) && max_range_m > 0.0)) {
    why << "max_range_m must be finite and > 0, got " << max_range_m;
  } else if (depth_stride_px < 1 || depth_stride_px > 64) {
    why << "depth_stride_px must be in [1, 64], got " << depth_stride_px;
  }
  return why.str();
}

OccupancyOctree::OccupancyOctree(const OctreeConfig& config) : config_(config) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("octree: " + why);
  tree_ = std::make_unique<octomap::OcTree>(config.resolution_m);
  tree_->setProbHit(config.prob_hit);
  tree_->setProbMiss(config.prob_miss);
}

OccupancyOctree::~OccupancyOctree() = default;
OccupancyOctree::OccupancyOctree(OccupancyOctree&&) noexcept = default;
OccupancyOctree& OccupancyOctree::operator=(OccupancyOctree&&) noexcept = default;

void OccupancyOctree::insertPoints(const std::vector<Eigen::Vector3d>& points,
                                   const Eigen::Vector3d& origin) {
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite())
      cloud.push_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                      static_cast<float>(p.z()));
  }
  tree_->insertPointCloud(
      cloud,
      octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                       static_cast<float>(origin.z())),
      config_.max_range_m);
}

void OccupancyOctree::insertDepth(const float* depth, const PinholeCamera& camera,
                                  const Eigen::Isometry3d& T_map_camera) {
  std::vector<Eigen::Vector3d> points;
  const int stride = config_.depth_stride_px;
  for (int v = stride / 2; v < camera.height; v += stride) {
    for (int u = stride / 2; u < camera.width; u += stride) {
      const float d = depth[static_cast<std::size_t>(v) * camera.width + u];
      if (!(d > 0.0f) || !std::isfinite(d)) continue;  // NaN, 0 and +Inf: no end point
      points.push_back(T_map_camera * Eigen::Vector3d((u - camera.cx) / camera.fx * d,
                                                      (v - camera.cy) / camera.fy * d, d));
    }
  }
  insertPoints(points, T_map_camera.translation());
}

bool OccupancyOctree::logOdds(const Eigen::Vector3d& p, double* log_odds) const {
  const octomap::OcTreeNode* node = tree_->search(p.x(), p.y(), p.z());
  if (node == nullptr) return false;
  *log_odds = node->getLogOdds();
  return true;
}

std::vector<Eigen::Vector3d> OccupancyOctree::occupiedCenters() const {
  std::vector<Eigen::Vector3d> out;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
    if (tree_->isNodeOccupied(*it)) out.emplace_back(it.getX(), it.getY(), it.getZ());
  }
  return out;
}

std::size_t OccupancyOctree::leafCount() const {
  return tree_->getNumLeafNodes();
}
std::size_t OccupancyOctree::memoryBytes() const {
  return tree_->memoryUsage();
}

std::string OccupancyOctree::writeBinary(const std::string& path) const {
  return tree_->writeBinary(path) ? std::string() : "could not write " + path;
}

bool OccupancyOctree::writeBinary(std::ostream& out) const {
  return tree_->writeBinaryConst(out);
}

void OccupancyOctree::clear() {
  tree_->clear();
}

}  // namespace downstream_perception
