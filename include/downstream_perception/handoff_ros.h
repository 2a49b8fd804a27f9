// ROS host of the perception-to-planning handoff ("downstream_perception/HandoffNodelet").
//
// Goals down: a PoseStamped on `goal` (any frame, usually map) is re-expressed in
// robot_base_frame with the transform at the goal's own stamp and published on ~goal_base; the
// ~transform_pose service does the same for any pose and target frame.
// Obstacles up: every TrackedObjectArray on the track topics is re-published on
// ~tracks_planning in planning_frame, transformed at its stamp (stamp kept).
// Seam health: per input (scans and tracks) the transform age now - stamp on arrival (p50, p95,
// max), the smear it causes at reference_range_m at the current yaw rate, and the map <- odom
// correction (magnitude, age, resets, sawtooth checks) on ~seam_health and diagnostics.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/SeamHealth.h"
#include "downstream_perception/TrackedObjectArray.h"
#include "downstream_perception/TransformPose.h"
#include "downstream_perception/core/seam_health.h"
#include "downstream_perception/filtered_subscription.h"

namespace downstream_perception {

class HandoffRos {
 public:
  HandoffRos(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  /// One watched input; its messages are released once they can be placed in planning_frame at
  /// their stamp (tf2 MessageFilter), so the recorded age is what a consumer experiences.
  struct Input {
    std::string topic;
    std::string type;
    FilteredSubscription<sensor_msgs::LaserScan> scans;
    FilteredSubscription<TrackedObjectArray> tracks;
    SampleWindow ages;
    std::size_t tf_failures = 0;
  };

  void loadParameters();
  Input& addInput(const std::string& topic, const std::string& type);
  void recordArrival(Input* input, const ros::Time& stamp);
  void onTfFailure(Input* input, const std::string& frame, const ros::Time& stamp,
                   tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void onTracks(Input* input, const TrackedObjectArrayConstPtr& msg);
  void onGoal(const geometry_msgs::PoseStampedConstPtr& msg);
  bool onTransformPose(TransformPose::Request& req, TransformPose::Response& res);
  /// The pose in target_frame at the pose's stamp; false with the reason in *why.
  bool transformPose(const geometry_msgs::PoseStamped& in, const std::string& target_frame,
                     geometry_msgs::PoseStamped* out, std::string* why);
  void onTimer(const ros::TimerEvent& event);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  std::string planning_frame_ = "map";
  std::string odom_frame_ = "odom";
  std::string robot_base_frame_ = "base_link";
  double reference_range_m_ = 5.0;
  double max_transform_age_s_ = 0.1;
  double max_smear_m_ = 0.05;
  double max_map_odom_age_s_ = 2.0;
  double health_rate_hz_ = 2.0;
  CorrectionMonitorConfig correction_config_;

  std::mutex mutex_;
  std::vector<std::unique_ptr<Input>> inputs_;
  CorrectionMonitor correction_;
  double yaw_rate_rps_ = 0.0;
  double travelled_m_ = 0.0;
  bool have_last_base_ = false;
  double last_base_x_ = 0.0, last_base_y_ = 0.0;
  SeamHealth health_;  ///< the last report, also what diagnostics show
  std::size_t goals_ = 0, goal_failures_ = 0;
  std::string last_goal_failure_;
  std::vector<std::string> config_errors_;

  ros::Publisher goal_publisher_, tracks_publisher_, health_publisher_;
  ros::Subscriber goal_subscriber_;
  ros::ServiceServer transform_service_;
  ros::Timer timer_;
  diagnostic_updater::Updater diagnostics_;
};

}  // namespace downstream_perception
