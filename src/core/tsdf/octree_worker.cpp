#include "downstream_perception/core/tsdf/octree_worker.h"

#include <chrono>
#include <stdexcept>
#include <utility>

namespace downstream_perception {

OctreeWorker::OctreeWorker(OccupancyOctree tree, std::size_t queue_size)
    : queue_size_(queue_size), tree_(std::move(tree)) {
  if (queue_size_ == 0) throw std::invalid_argument("octree worker: queue_size must be >= 1");
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
    busy_ = true;
    lock.unlock();
    double ms = 0.0;
    std::size_t leaves = 0, memory_bytes = 0;
    bool counted = false;
    {
      std::lock_guard<std::mutex> tree_lock(tree_mutex_);
      const auto t0 = std::chrono::steady_clock::now();
      if (o.depth.empty()) {
        tree_.insertPoints(o.points, o.pose.translation());
      } else {
        tree_.insertDepth(o.depth.data(), o.camera, o.pose);
      }
      ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      // Counting walks the tree twice (about 4 ms for 56,000 leaves, a tenth of an insertion):
      // skipped while observations wait, when the thread's time matters.
      bool backlog;
      {
        std::lock_guard<std::mutex> queue_lock(queue_mutex_);  // order: tree, then queue
        backlog = !queue_.empty();
      }
      if (!backlog) {
        leaves = tree_.leafCount();
        memory_bytes = tree_.memoryBytes();
        counted = true;
      }
    }
    lock.lock();
    busy_ = false;
    changed_ = true;
    ++stats_.inserted;
    stats_.insert_ms.add(ms);
    if (counted) {
      stats_.leaves = leaves;
      stats_.memory_bytes = memory_bytes;
    }
    if (queue_.empty()) idle_.notify_all();
  }
}

void OctreeWorker::clear() {
  std::lock_guard<std::mutex> tree_lock(tree_mutex_);  // waits for an insertion under way
  std::lock_guard<std::mutex> lock(queue_mutex_);
  queue_.clear();
  tree_.clear();
  stats_.leaves = tree_.leafCount();
  stats_.memory_bytes = tree_.memoryBytes();
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
