#include "downstream_perception/core/tsdf/octree_worker.h"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <utility>

namespace downstream_perception {

OctreeWorker::OctreeWorker(OccupancyOctree tree, std::size_t queue_size,
                           std::size_t maintenance_every)
    : queue_size_(queue_size), maintenance_every_(maintenance_every), tree_(std::move(tree)) {
  if (queue_size_ == 0) throw std::invalid_argument("octree worker: queue_size must be >= 1");
  if (maintenance_every_ == 0) {
    throw std::invalid_argument("octree worker: maintenance_every must be >= 1");
  }
  thread_ = std::thread(&OctreeWorker::run, this);
}

OctreeWorker::~OctreeWorker() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stop_ = true;
    queue_.clear();
  }
  wake_.notify_all();
  thread_.join();
}

void OctreeWorker::submitDepth(std::vector<float> depth, const PinholeCamera& camera,
                               const Eigen::Isometry3d& T_map_camera) {
  Observation o;
  o.depth = std::move(depth);
  o.camera = camera;
  o.pose = T_map_camera;
  push(std::move(o));
}

void OctreeWorker::submitPoints(std::vector<Eigen::Vector3d> points,
                                const Eigen::Vector3d& origin) {
  Observation o;
  o.points = std::move(points);
  o.pose.translation() = origin;
  push(std::move(o));
}

void OctreeWorker::push(Observation observation) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.size() >= queue_size_) {
      queue_.pop_front();
      ++stats_.dropped;
    }
    queue_.push_back(std::move(observation));
  }
  wake_.notify_one();
}

void OctreeWorker::run() {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    Observation o = std::move(queue_.front());
    queue_.pop_front();
    const std::optional<double> max_distance_m = std::exchange(pending_max_distance_m_, {});
    busy_ = true;
    lock.unlock();
    double ms = 0.0;
    std::size_t nodes = 0, leaves = 0, memory_bytes = 0;
    OctreeMaintenance maintenance;
    double maintenance_ms = 0.0;
    bool counted = false, maintained = false;
    {
      std::lock_guard<std::mutex> tree_lock(tree_mutex_);
      if (max_distance_m) tree_.setBounds(*max_distance_m, tree_.config().max_memory_bytes);
      const auto t0 = std::chrono::steady_clock::now();
      if (o.depth.empty()) {
        tree_.insertPoints(o.points, o.pose.translation());
      } else {
        tree_.insertDepth(o.depth.data(), o.camera, o.pose);
      }
      ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      bool backlog;
      {
        std::lock_guard<std::mutex> queue_lock(queue_mutex_);  // order: tree, then queue
        backlog = !queue_.empty();
      }
      insert(o, backlog);
      nodes = tree_.nodeCount();
      counted = counted_;
      maintained = maintained_;
      leaves = last_maintenance_.leaves;
      memory_bytes = last_maintenance_.memory_bytes;
      maintenance = last_maintenance_;
      maintenance_ms = last_maintenance_ms_;
    }
    lock.lock();
    busy_ = false;
    changed_ = true;
    ++stats_.inserted;
    stats_.insert_ms.add(ms);
    stats_.nodes = nodes;
    if (counted) {
      stats_.leaves = leaves;
      stats_.memory_bytes = memory_bytes;
    }
    if (maintained) {
      ++stats_.maintenances;
      stats_.maintenance_ms.add(maintenance_ms);
      stats_.nodes_evicted_by_distance += maintenance.nodes_evicted_by_distance;
      stats_.nodes_evicted_at_cap += maintenance.nodes_evicted_at_cap;
    }
    if (queue_.empty()) idle_.notify_all();
  }
}

void OctreeWorker::insert(const Observation& o, bool backlog) {
  // Counting walks the tree (about 4 ms for 56,000 leaves, a tenth of an insertion), and so
  // does maintenance: both every maintenance_every insertions, or at the memory cap; between
  // them a count only when no observation waits, when the thread's time does not matter.
  const std::size_t cap = tree_.config().max_memory_bytes;
  const bool at_cap = cap > 0 && static_cast<double>(tree_.nodeCount()) * bytes_per_node_ >
                                     static_cast<double>(cap);
  maintained_ = ++since_maintenance_ >= maintenance_every_ || at_cap;
  counted_ = maintained_ || !backlog;
  if (maintained_) {
    const auto t0 = std::chrono::steady_clock::now();
    last_maintenance_ = tree_.maintain(o.pose.translation());
    last_maintenance_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    since_maintenance_ = 0;
  } else if (counted_) {
    last_maintenance_ = OctreeMaintenance{};  // nothing evicted by this count
    last_maintenance_.leaves = tree_.leafCount();
    last_maintenance_.memory_bytes = tree_.memoryBytes();
  }
  const std::size_t nodes = tree_.nodeCount();
  if (counted_ && nodes > 0) {
    bytes_per_node_ =
        static_cast<double>(last_maintenance_.memory_bytes) / static_cast<double>(nodes);
  }
}

std::string OctreeWorker::setMaxDistance(double max_distance_m) {
  OctreeConfig check;  // the defaults are valid: validate() judges the distance
  check.max_distance_m = max_distance_m;
  const std::string why = check.validate();
  if (!why.empty()) return why;
  std::lock_guard<std::mutex> lock(queue_mutex_);
  pending_max_distance_m_ = max_distance_m;
  return {};
}

void OctreeWorker::clear() {
  std::lock_guard<std::mutex> tree_lock(tree_mutex_);  // waits for an insertion under way
  std::lock_guard<std::mutex> lock(queue_mutex_);
  queue_.clear();
  tree_.clear();
  stats_.leaves = tree_.leafCount();
  stats_.memory_bytes = tree_.memoryBytes();
  stats_.nodes = tree_.nodeCount();
  changed_ = true;
  idle_.notify_all();
}

bool OctreeWorker::takeChanged() {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  return std::exchange(changed_, false);
}

void OctreeWorker::waitIdle() {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

OctreeWorker::Stats OctreeWorker::stats() const {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  Stats s = stats_;
  s.waiting = queue_.size();
  return s;
}

}  // namespace downstream_perception
