// A PointCloud2 observation source (depth cameras, 3-D lidars): the cloud is placed in the
// global frame with the transform at its own stamp; points inside the obstacle height band mark
// and clear from the sensor origin (see core/cloud_beams.h). Needs x, y, z as consecutive
// FLOAT32 fields (every PCL and driver layout).
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include "downstream_perception/layers/observation_source.h"

namespace downstream_perception {

class PointCloudSource : public ObservationSource {
 public:
  PointCloudSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                   tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation);
  ~PointCloudSource() override { unsubscribe(); }

  void subscribe() override;
  void unsubscribe() override { subscription_.unsubscribe(); }
  std::vector<TfWait> waitingForTf() const override { return subscription_.waitingForTf(); }
  const char* dataType() const override { return "PointCloud2"; }

 private:
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& msg);

  FilteredSubscription<sensor_msgs::PointCloud2> subscription_;
};

}  // namespace downstream_perception
