#include "downstream_perception/core/tsdf/occupancy_octree.h"

#include <octomap/OcTree.h>

#include <algorithm>
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
  } else if (!(max_range_m > 0.0 && max_range_m <= 1000.0)) {
    // Beyond every depth sensor; a 1e300 m ray never finished casting.
    why << "max_range_m must be in (0, 1000] m, got " << max_range_m;
  } else if (depth_stride_px < 1 || depth_stride_px > 64) {
    why << "depth_stride_px must be in [1, 64], got " << depth_stride_px;
  } else if (!(std::isfinite(max_distance_m) && max_distance_m >= 0.0)) {
    why << "max_distance_m must be finite and >= 0 (0 = never evict), got " << max_distance_m;
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
  const double range = config_.max_distance_m > 0.0
                           ? std::min(config_.max_range_m, config_.max_distance_m)
                           : config_.max_range_m;
  tree_->insertPointCloud(
      cloud,
      octomap::point3d(static_cast<float>(origin.x()), static_cast<float>(origin.y()),
                       static_cast<float>(origin.z())),
      range);
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

namespace {

using Node = octomap::OcTreeNode;

/// Deletes the subtrees beyond a sphere from an octomap::OcTree through its public interface
/// only. octomap's own deleteNode() cannot be used for this: it deletes an inner node without
/// its children (they leak) and leaves emptied child arrays behind.
class SphereEviction {
 public:
  SphereEviction(octomap::OcTree* tree, const Eigen::Vector3d& center, double radius)
      : tree_(tree), center_(center), radius2_(radius * radius) {}

  std::size_t run() {
    Node* root = tree_->getRoot();
    if (root == nullptr) return 0;
    const std::size_t before = tree_->size();
    const double side = tree_->getResolution() * static_cast<double>(1u << tree_->getTreeDepth());
    if (visit(root, Eigen::Vector3d::Constant(-0.5 * side), side)) tree_->clear();
    return before - tree_->size();
  }

 private:
  /// Removes what lies beyond the sphere under `node` (a cube at `lo` with edge `side`);
  /// true if nothing of it is left, so the caller deletes the node itself.
  bool visit(Node* node, const Eigen::Vector3d& lo, double side) {
    const Eigen::Vector3d hi = lo + Eigen::Vector3d::Constant(side);
    const Eigen::Vector3d nearest = center_.cwiseMax(lo).cwiseMin(hi);
    if ((nearest - center_).squaredNorm() > radius2_) return true;  // all beyond
    const Eigen::Vector3d farthest =
        ((center_ - lo).cwiseAbs().array() > (center_ - hi).cwiseAbs().array()).select(lo, hi);
    if ((farthest - center_).squaredNorm() <= radius2_) return false;  // all within
    if (!tree_->nodeHasChildren(node)) {
      return (lo + Eigen::Vector3d::Constant(0.5 * side) - center_).squaredNorm() > radius2_;
    }
    const double half = 0.5 * side;
    bool lost = false;
    for (unsigned int i = 0; i < 8; ++i) {
      if (!tree_->nodeChildExists(node, i)) continue;
      const Eigen::Vector3d child_lo =
          lo +
          half * Eigen::Vector3d((i & 1) ? 1.0 : 0.0, (i & 2) ? 1.0 : 0.0, (i & 4) ? 1.0 : 0.0);
      Node* child = tree_->getNodeChild(node, i);
      if (visit(child, child_lo, half)) {
        freeChildren(child);
        tree_->deleteNodeChild(node, i);
        lost = true;
      }
    }
    if (!lost) return false;
    if (tree_->nodeHasChildren(node)) {
      node->updateOccupancyChildren();  // the maximum of the children left
      return false;
    }
    // Every child gone: free the node's (now empty) child array before it is deleted, through
    // expandNode (8 leaves into the existing array) and pruneNode (deletes them and the array).
    tree_->expandNode(node);
    tree_->pruneNode(node);
    return true;
  }

  /// Deletes every descendant of `node` and its child array (octomap's node destructor frees
  /// neither): bottom up, each node's children are completed to 8 equal leaves and pruned.
  void freeChildren(Node* node) {
    if (!tree_->nodeHasChildren(node)) return;
    for (unsigned int i = 0; i < 8; ++i) {
      if (tree_->nodeChildExists(node, i)) {
        freeChildren(tree_->getNodeChild(node, i));
      } else {
        tree_->createNodeChild(node, i);
      }
      tree_->getNodeChild(node, i)->copyData(*node);
    }
    tree_->pruneNode(node);
  }

  octomap::OcTree* tree_;
  Eigen::Vector3d center_;
  double radius2_;
};

}  // namespace

std::size_t OccupancyOctree::evictFartherThan(const Eigen::Vector3d& center, double distance_m) {
  if (!center.allFinite() || !(distance_m >= 0.0)) return 0;
  return SphereEviction(tree_.get(), center, distance_m).run();
}

OctreeMaintenance OccupancyOctree::maintain(const Eigen::Vector3d& sensor_origin) {
  OctreeMaintenance m;
  if (config_.max_distance_m > 0.0) {
    m.nodes_evicted_by_distance = evictFartherThan(sensor_origin, config_.max_distance_m);
  }
  tree_->prune();
  m.memory_bytes = memoryBytes();
  const std::size_t cap = config_.max_memory_bytes;
  // At the cap: keep the leaves nearest the sensor, as many as should fit in 90 % of it (nodes
  // and memory do not shrink exactly with the leaves, hence a few rounds).
  for (int round = 0; round < 4 && cap > 0 && m.memory_bytes > cap && sensor_origin.allFinite();
       ++round) {
    std::vector<double> distances;
    distances.reserve(tree_->size());
    for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
      distances.push_back(
          (Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - sensor_origin).norm());
    }
    if (distances.empty()) break;
    const double keep = 0.9 * static_cast<double>(cap) / static_cast<double>(m.memory_bytes);
    const auto k = static_cast<std::size_t>(keep * static_cast<double>(distances.size()));
    std::nth_element(distances.begin(), distances.begin() + k, distances.end());
    // Leaves exactly at the k-th distance stay; at k = 0 the nearest leaf is the radius.
    m.nodes_evicted_at_cap += evictFartherThan(sensor_origin, distances[k]);
    if (k == 0) m.nodes_evicted_at_cap += evictFartherThan(sensor_origin, 0.0);
    m.memory_bytes = memoryBytes();
  }
  m.leaves = leafCount();
  return m;
}

std::string OccupancyOctree::setBounds(double max_distance_m, std::size_t max_memory_bytes) {
  OctreeConfig next = config_;
  next.max_distance_m = max_distance_m;
  next.max_memory_bytes = max_memory_bytes;
  std::string why = next.validate();
  if (why.empty()) config_ = next;
  return why;
}

std::size_t OccupancyOctree::nodeCount() const {
  return tree_->size();
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
