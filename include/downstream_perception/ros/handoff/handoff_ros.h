// ROS host of the perception-to-planning handoff ("downstream_perception/HandoffNodelet").
//
// Goals down: a PoseStamped on `goal` (any frame, usually map) is re-expressed in
// robot_base_frame with the transform at the goal's own stamp and published on ~goal_base; the
// ~transform_pose service does the same for any pose and target frame.
// Obstacles up: scans, clouds and tracks re-published in planning_frame at their own stamps
// (PlanningFrameRelay).
// Seam health: per input the transform age now - stamp on arrival (p50, p95, max), the smear it
// causes at reference_range_m at the current yaw rate, and the map <- odom correction (magnitude,
// age, resets, sawtooth checks) on ~seam_health and diagnostics; limits live through
// dynamic_reconfigure.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/HandoffConfig.h"
#include "downstream_perception/SeamHealth.h"
#include "downstream_perception/TransformPose.h"
#include "downstream_perception/core/handoff/seam_health.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/handoff/planning_frame_relay.h"

namespace downstream_perception {

class HandoffRos {
 public:
  HandoffRos(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  void loadParameters();
  void reconfigure(HandoffConfig& config, std::uint32_t level);
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
  double health_rate_hz_ = 2.0;
  CorrectionMonitorConfig correction_config_;
  std::unique_ptr<PlanningFrameRelay> relay_;

  std::mutex mutex_;  ///< guards everything below
  SeamLimits limits_;
  CorrectionMonitor correction_;
  double yaw_rate_rps_ = 0.0;
  double travelled_m_ = 0.0;
  bool have_last_base_ = false;
  double last_base_x_ = 0.0, last_base_y_ = 0.0;
  SeamHealth health_;  ///< the last report, also what diagnostics show
  std::size_t goals_ = 0, goal_failures_ = 0, goals_rejected_ = 0;
  std::string last_goal_failure_;
  ConfigErrorLog config_errors_;

  ros::Publisher goal_publisher_, health_publisher_;
  ros::Subscriber goal_subscriber_;
  ros::ServiceServer transform_service_;
  ros::Timer timer_;
  diagnostic_updater::Updater diagnostics_;
  ReconfigureHost<HandoffConfig> reconfigure_;
};

}  // namespace downstream_perception
