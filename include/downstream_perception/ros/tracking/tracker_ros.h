// ROS host of the Tracker: detections in (DetectedObjectArray), tracks out (TrackedObjectArray +
// rviz markers), in a fixed tracking frame. Metric detections are transformed with tf2 at their own
// stamp (a MessageFilter holds them until that transform exists), so the robot's own motion
// never shows up as object velocity. The nodelet and the node are thin shells around it.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/DetectedObjectArray.h"
#include "downstream_perception/TrackerNodeConfig.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/core/tracking/tracker.h"
#include "downstream_perception/ros/common/clock_jump.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/common/rejection_counter.h"
#include "downstream_perception/ros/tracking/track_markers.h"

namespace downstream_perception {

class TrackerRos {
 public:
  TrackerRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~TrackerRos();

 private:
  void reconfigure(TrackerNodeConfig& cfg, std::uint32_t level);
  /// Writes the mode's own defaults (TrackerConfig::modeSpecificDefaults) to the private
  /// parameters the user left unset, before the reconfigure server reads them; logs which.
  void applyModeDefaults(TrackerConfig::Mode mode);
  void onDetections(const DetectedObjectArrayConstPtr& msg);
  void onTfFailure(const DetectedObjectArrayConstPtr& msg,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  /// Converts (and for metric detections transforms) one message; false with a reason if the
  /// whole message must be dropped.
  bool toCore(const DetectedObjectArray& msg, std::vector<Detection>* out, std::string* why);
  void publish(const std_msgs::Header& header);
  /// Resets the tracks and tf when the ROS clock went back; else updates the diagnostics.
  void watchClock(const ros::SteadyTimerEvent&);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  std::string tracking_frame_;
  bool image_mode_ = false;
  std::mutex mutex_;  ///< guards tracker_ and the counters
  std::unique_ptr<Tracker> tracker_;
  std::map<int, std::string> labels_;  ///< class id -> last label seen

  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<message_filters::Subscriber<DetectedObjectArray>> subscriber_;  ///< image mode
  FilteredSubscription<DetectedObjectArray> filtered_;  ///< metric mode: released by tf
  ros::Publisher tracks_publisher_;
  ros::Publisher markers_publisher_;
  TrackMarkers markers_;
  diagnostic_updater::Updater diagnostics_;
  ReconfigureHost<TrackerNodeConfig> reconfigure_;

  // Diagnostics.
  TrackerStats total_;
  TrackerStats last_;
  std::size_t frames_ = 0;
  RejectionCounter rejected_{"tracker: detections rejected"};
  ClockJumpDetector clock_jump_;
  std::size_t detections_unknown_kind_ = 0;
  ros::SteadyTimer clock_watch_;
  TimingStats step_us_;
  ConfigErrorLog config_errors_{"tracker"};
};

}  // namespace downstream_perception
