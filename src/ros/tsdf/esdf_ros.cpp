#include "downstream_perception/ros/tsdf/esdf_ros.h"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <chrono>
#include <cmath>

namespace downstream_perception {

sensor_msgs::PointCloud2Ptr esdfSliceCloud(const Esdf& esdf, double z_m,
                                           const std_msgs::Header& header) {
  const double s = esdf.voxelSize();
  const int layer = static_cast<int>(std::lround(z_m / s));
  const int block_z = TsdfMap::blockOf({0, 0, layer}).z();
  const int local_z = layer - block_z * kTsdfBlockSide;
  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2Fields(
      4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "distance", 1, sensor_msgs::PointField::FLOAT32);
  const int first = local_z * kTsdfBlockSide * kTsdfBlockSide;
  const int end = first + kTsdfBlockSide * kTsdfBlockSide;
  std::size_t known = 0;
  for (const auto& [key, block] : esdf.blocks()) {
    if (key.z() != block_z) continue;
    for (int i = first; i < end; ++i) known += !std::isnan(block->distance[i]);
  }
  modifier.resize(known);
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z"),
      d(*cloud, "distance");
  for (const auto& [key, block] : esdf.blocks()) {
    if (key.z() != block_z) continue;
    for (int i = first; i < end; ++i) {
      if (std::isnan(block->distance[i])) continue;
      const int local = i - first;
      *x = static_cast<float>((key.x() * kTsdfBlockSide + local % kTsdfBlockSide) * s);
      *y = static_cast<float>((key.y() * kTsdfBlockSide + local / kTsdfBlockSide) * s);
      *z = static_cast<float>(layer * s);
      *d = block->distance[i];
      ++x, ++y, ++z, ++d;
    }
  }
  return cloud;
}

EsdfRos::EsdfRos(ros::NodeHandle& pnh, const EsdfConfig& config, double slice_z_m,
                 const TsdfMap* map, std::mutex* map_mutex)
    : map_(map), map_mutex_(map_mutex), esdf_(config, map->voxelSize()), slice_z_m_(slice_z_m) {
  slice_publisher_ = pnh.advertise<sensor_msgs::PointCloud2>("esdf_slice", 1, true);
  distance_service_ = pnh.advertiseService("esdf_distance", &EsdfRos::distance, this);
}

void EsdfRos::updateLocked() {
  const auto t0 = std::chrono::steady_clock::now();
  last_ = esdf_.update(*map_);
  update_ms_.add(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
}

sensor_msgs::PointCloud2Ptr EsdfRos::sliceLocked(const std_msgs::Header& header) {
  if (slice_publisher_.getNumSubscribers() == 0) return nullptr;
  updateLocked();
  return esdfSliceCloud(esdf_, slice_z_m_, header);
}

bool EsdfRos::distance(EsdfDistance::Request& request, EsdfDistance::Response& response) {
  std::lock_guard<std::mutex> lock(*map_mutex_);
  updateLocked();
  ++queries_;
  const std::size_t n = request.points.size();
  response.distances.resize(n);
  response.gradients.resize(n);
  response.observed.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const geometry_msgs::Point& p = request.points[i];
    const EsdfSample s = esdf_.sample({p.x, p.y, p.z});
    response.distances[i] = s.distance;
    response.gradients[i].x = s.gradient.x();
    response.gradients[i].y = s.gradient.y();
    response.gradients[i].z = s.gradient.z();
    response.observed[i] = s.observed;
  }
  return true;
}

void EsdfRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  status.add("esdf: max distance (m)", esdf_.config().max_distance_m);
  status.add("esdf: blocks", esdf_.blockCount());
  status.add("esdf: memory (MB)", static_cast<double>(esdf_.memoryBytes()) / 1e6);
  status.add("esdf: updates", update_ms_.count);
  status.add("esdf: update time mean (ms)", update_ms_.mean());
  status.add("esdf: update time max (ms)", update_ms_.max);
  status.add("esdf: last update: voxels changed", last_.voxels_changed);
  status.add("esdf: last update: blocks recomputed", last_.blocks_written);
  status.add("esdf: distance queries", queries_);
}

}  // namespace downstream_perception
