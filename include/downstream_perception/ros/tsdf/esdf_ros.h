// The TSDF nodelet's ESDF (core/tsdf/esdf.h) on ROS: the ~esdf_distance service (distance and
// gradient at points) and ~esdf_slice, a PointCloud2 of the ESDF's voxel layer at one height
// with a float32 `distance` channel that rviz colours by (voxblox's ESDF slice). The ESDF is
// updated incrementally from the map, under the map's mutex, before each query and at each
// mesh tick while the slice has subscribers.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <mutex>
#include <string>

#include "downstream_perception/EsdfDistance.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

/// Points (x, y, z = the layer's height, distance: float32, m) at the centres of the known
/// voxels of the ESDF's layer nearest z_m.
sensor_msgs::PointCloud2Ptr esdfSliceCloud(const Esdf& esdf, double z_m,
                                           const std_msgs::Header& header);

class EsdfRos {
 public:
  /// `map` and `map_mutex` belong to the TsdfRos that owns this and outlive it. Throws
  /// std::invalid_argument if config does not suit the map's voxel size.
  EsdfRos(ros::NodeHandle& pnh, const EsdfConfig& config, double slice_z_m, const TsdfMap* map,
          std::mutex* map_mutex);
  /// At the mesh tick, with the map's mutex held: the slice to publish, or null when nobody
  /// subscribes to ~esdf_slice (then the ESDF is not updated).
  sensor_msgs::PointCloud2Ptr sliceLocked(const std_msgs::Header& header);
  void publish(const sensor_msgs::PointCloud2Ptr& slice) { slice_publisher_.publish(slice); }
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) const;

 private:
  void updateLocked();
  bool distance(EsdfDistance::Request& request, EsdfDistance::Response& response);

  const TsdfMap* map_;
  std::mutex* map_mutex_;
  Esdf esdf_;
  double slice_z_m_;
  ros::Publisher slice_publisher_;
  ros::ServiceServer distance_service_;
  RunningStats update_ms_;  ///< guarded by map_mutex_, as esdf_
  EsdfUpdateStats last_;
  std::size_t queries_ = 0;
};

}  // namespace downstream_perception
