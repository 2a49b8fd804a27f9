// Obstacles up, for the handoff nodelet: every watched input (LaserScan, PointCloud2,
// TrackedObjectArray) is released by a tf2 MessageFilter once it can be placed in the planning
// frame at its own stamp, checked, transformed with that transform and re-published with its
// stamp kept: scans as PointCloud2 on ~scans_planning (laser_geometry, each beam at its own time),
// clouds on ~clouds_planning (tf2_sensor_msgs), tracks on ~tracks_planning. For each input it
// records the transform age now - stamp on release, tf failures and malformed messages.
#pragma once

#include <laser_geometry/laser_geometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/SeamInput.h"
#include "downstream_perception/TrackedObjectArray.h"
#include "downstream_perception/core/handoff/seam_health.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/rejection_counter.h"

namespace downstream_perception {

struct RelayTopics {
  std::vector<std::string> scans, clouds, tracks;
  bool republish = true;   ///< false: only watch the transform ages
  int tf_queue_size = 20;  ///< messages per input held while their transform is awaited
};

class PlanningFrameRelay {
 public:
  PlanningFrameRelay(ros::NodeHandle nh, ros::NodeHandle pnh, tf2_ros::Buffer& tf,
                     std::string planning_frame, const RelayTopics& topics);

  /// Per input: topic, type, counts and transform-age percentiles (the smear is the caller's).
  std::vector<SeamInput> inputs() const;
  /// Per input topic: the messages held back for their transform for a while.
  std::vector<std::pair<std::string, std::vector<TfWait>>> waitingForTf() const;

 private:
  struct Input {
    std::string topic;
    std::string type;
    FilteredSubscription<sensor_msgs::LaserScan> scans;
    FilteredSubscription<sensor_msgs::PointCloud2> clouds;
    FilteredSubscription<TrackedObjectArray> tracks;
    SampleWindow ages;
    std::size_t tf_failures = 0;
    RejectionCounter rejected;  ///< one reason: the diagnostics show one "malformed" count
    ros::Duration scan_sweep;   ///< longest scan duration seen: tf is awaited to its last beam
  };

  Input& addInput(const std::string& topic, const std::string& type);
  template <class M>
  void watch(Input* input, FilteredSubscription<M>* subscription,
             void (PlanningFrameRelay::*on_message)(Input*, const boost::shared_ptr<const M>&));
  /// Records the age; false (and counted) for a zero stamp.
  bool arrive(Input* input, const ros::Time& stamp);
  void onTfFailure(Input* input, const std::string& frame, const ros::Time& stamp,
                   const std::string& why);
  void onScan(Input* input, const sensor_msgs::LaserScanConstPtr& msg);
  void onCloud(Input* input, const sensor_msgs::PointCloud2ConstPtr& msg);
  void onTracks(Input* input, const TrackedObjectArrayConstPtr& msg);

  ros::NodeHandle nh_, pnh_;
  tf2_ros::Buffer& tf_;
  const std::string planning_frame_;
  const bool republish_;
  const int tf_queue_size_;
  mutable std::mutex mutex_;  ///< guards the inputs' counters and age windows
  std::vector<std::unique_ptr<Input>> inputs_;
  std::mutex projector_mutex_;  ///< LaserProjection caches its beam tables
  laser_geometry::LaserProjection projector_;
  ros::Publisher scans_publisher_, clouds_publisher_, tracks_publisher_;
};

}  // namespace downstream_perception
