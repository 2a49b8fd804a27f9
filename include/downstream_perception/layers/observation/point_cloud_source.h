// A point cloud observation source (depth cameras, 3-D lidars): sensor_msgs/PointCloud2, or
// costmap_2d's data_type PointCloud (sensor_msgs/PointCloud, converted to a PointCloud2 and then
// handled the same way). The cloud is placed in the global frame with the transform at its own
// stamp; points inside the obstacle height band mark and clear from the sensor origin (see
// core/cloud_beams.h). Needs x, y, z as consecutive FLOAT32 fields (every PCL and driver layout).
#pragma once

#include <sensor_msgs/PointCloud.h>
#include <sensor_msgs/PointCloud2.h>

#include "downstream_perception/layers/observation/observation_source.h"

namespace downstream_perception {

class PointCloudSource : public ObservationSource {
 public:
  /// `legacy`: subscribe to sensor_msgs/PointCloud (costmap_2d's data_type PointCloud).
  PointCloudSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                   tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation,
                   bool legacy = false);
  ~PointCloudSource() override { unsubscribe(); }

  void subscribe() override;
  void unsubscribe() override {
    subscription_.unsubscribe();
    legacy_subscription_.unsubscribe();
    markUnsubscribed();
  }
  std::vector<TfWait> waitingForTf() const override {
    return legacy_ ? legacy_subscription_.waitingForTf() : subscription_.waitingForTf();
  }
  const char* dataType() const override { return legacy_ ? "PointCloud" : "PointCloud2"; }
  std::string resolvedTopic() const override {
    return legacy_ ? legacy_subscription_.topic() : subscription_.topic();
  }
  std::uint32_t numPublishers() const override {
    return legacy_ ? legacy_subscription_.numPublishers() : subscription_.numPublishers();
  }

 private:
  void onCloud(const sensor_msgs::PointCloud2& msg);
  void onLegacyCloud(const sensor_msgs::PointCloudConstPtr& msg);

  bool legacy_;
  FilteredSubscription<sensor_msgs::PointCloud2> subscription_;
  FilteredSubscription<sensor_msgs::PointCloud> legacy_subscription_;
};

}  // namespace downstream_perception
