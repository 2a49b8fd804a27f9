// A LaserScan observation source: REP-117 range semantics, upside-down mounting, and per-beam
// time correction (each beam cast from the sensor pose at its own time, interpolated between the
// transforms at the first and the last beam) when the driver fills time_increment.
#pragma once

#include <sensor_msgs/LaserScan.h>

#include "downstream_perception/layers/observation_source.h"

namespace downstream_perception {

class LaserScanSource : public ObservationSource {
 public:
  LaserScanSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                  tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation);
  ~LaserScanSource() override { unsubscribe(); }

  void subscribe() override;
  void unsubscribe() override { subscription_.unsubscribe(); }
  std::vector<TfWait> waitingForTf() const override { return subscription_.waitingForTf(); }
  const char* dataType() const override { return "LaserScan"; }

 private:
  void onScan(const sensor_msgs::LaserScanConstPtr& msg);
  /// Planar sensor pose at `stamp`; false (with a rejection) on a tf failure or a tilted sensor.
  bool sensorPose(const std::string& frame, const ros::Time& stamp, bool reject_on_failure,
                  Pose2D* pose, bool* upside_down);

  FilteredSubscription<sensor_msgs::LaserScan> subscription_;
  ros::Duration tolerance_;  ///< longest sweep seen: the filter waits for tf at its last beam
};

}  // namespace downstream_perception
