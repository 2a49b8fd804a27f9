// A LaserScan observation source: REP-117 range semantics, upside-down mounting, and per-beam
// time correction (each beam cast from the sensor pose at its own time, interpolated between the
// transforms at the first and the last beam) when the driver fills time_increment. As in
// costmap_2d, a beam whose end lies outside the height band in the global frame neither marks
// nor clears, and costmap_2d's inf_is_valid turns +Inf into a return just inside range_max.
#pragma once

#include <sensor_msgs/LaserScan.h>

#include "downstream_perception/layers/observation/observation_source.h"
#include "downstream_perception/layers/observation/scan_height_band.h"

namespace downstream_perception {

class LaserScanSource : public ObservationSource {
 public:
  LaserScanSource(std::string name, const ObservationSourceConfig& config, ros::NodeHandle nh,
                  tf2_ros::Buffer& tf, std::string global_frame, Callback on_observation);
  ~LaserScanSource() override { unsubscribe(); }

  void subscribe() override;
  void unsubscribe() override {
    subscription_.unsubscribe();
    markUnsubscribed();
  }
  std::vector<TfWait> waitingForTf() const override { return subscription_.waitingForTf(); }
  const char* dataType() const override { return "LaserScan"; }
  std::string resolvedTopic() const override { return subscription_.topic(); }
  std::uint32_t numPublishers() const override { return subscription_.numPublishers(); }

 private:
  void onScan(const sensor_msgs::LaserScanConstPtr& msg);
  /// Planar sensor pose at `stamp`; false (with a rejection) on a tf failure or a tilted sensor.
  bool sensorPose(const std::string& frame, const ros::Time& stamp, bool reject_on_failure,
                  Pose2D* pose, bool* upside_down, ScanHeightModel* heights = nullptr);

  FilteredSubscription<sensor_msgs::LaserScan> subscription_;
  ros::Duration tolerance_;    ///< longest sweep seen: the filter waits for tf at its last beam
  std::vector<float> ranges_;  ///< the ranges after the height band (reused between scans)
};

}  // namespace downstream_perception
