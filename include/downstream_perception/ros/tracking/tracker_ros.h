// ROS host of the Tracker: detections in (DetectedObjectArray), tracks out (TrackedObjectArray +
// rviz markers), in a fixed tracking frame. Metric detections are transformed with tf2 at their own
// stamp (a MessageFilter holds them until that transform exists), so the robot's own motion
// never shows up as object velocity. The nodelet and the node are thin shells around it.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>
#include <boost/thread/recursive_mutex.hpp>

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
#include "downstream_perception/ros/common/filtered_subscription.h"
#include "downstream_perception/ros/tracking/track_markers.h"

namespace downstream_perception {

class TrackerRos {
 public:
  TrackerRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~TrackerRos();

 private:
  using ReconfigureServer = dynamic_reconfigure::Server<TrackerNodeConfig>;
  void reconfigure(TrackerNodeConfig& cfg, std::uint32_t level);
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
  void reject(const std::string& reason, const std::string& detail);

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
  boost::recursive_mutex reconfigure_mutex_;  // the type dynamic_reconfigure::Server takes
  std::unique_ptr<ReconfigureServer> reconfigure_server_;

  // Diagnostics.
  TrackerStats total_;
  TrackerStats last_;
  std::size_t frames_ = 0;
  std::map<std::string, std::size_t> rejected_;
  ClockJumpDetector clock_jump_;
  std::size_t detections_unknown_kind_ = 0;
  ros::SteadyTimer clock_watch_;
  RunningStats step_us_;
  std::vector<std::string> config_errors_;
};

}  // namespace downstream_perception
