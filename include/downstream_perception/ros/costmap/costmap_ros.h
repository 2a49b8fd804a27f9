// ROS host of a LayeredCostmap: parameters (YAML + dynamic_reconfigure), plugin loading, the
// update timer (rolling window included), publishing (~costmap, ~costmap_updates, ~footprint),
// the ~clear service and diagnostics. The nodelet and the node are thin shells around it.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PolygonStamped.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <pluginlib/class_loader.hpp>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/CostmapConfig.h"
#include "downstream_perception/core/running_stats.h"
#include "downstream_perception/ros/common/clock_jump.h"
#include "downstream_perception/ros/common/reconfigure_host.h"
#include "downstream_perception/ros/costmap/costmap_publisher.h"
#include "downstream_perception/ros/costmap/costmap_ros_config.h"
#include "downstream_perception/ros/costmap/data_update_trigger.h"
#include "downstream_perception/ros/costmap/layered_costmap.h"

namespace downstream_perception {

class CostmapRos {
 public:
  CostmapRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~CostmapRos();

  LayeredCostmap& layeredCostmap() { return *layered_costmap_; }

 private:
  void loadPlugins();
  /// WARNs for host-level keys nobody reads (after the layers are loaded).
  void auditKeys(ParamReader& params);
  void reconfigure(CostmapConfig& cfg, std::uint32_t level);
  void updateTimerCallback(const ros::TimerEvent& event);
  /// update_on_data: a layer integrated new data (on the trigger's thread).
  void onDataArrived();
  /// One update of the master, then a publish if due; update_mutex_ held by the caller.
  void updateAndPublish(bool on_data);
  /// Resets what depends on time when the ROS clock went back.
  void watchClock(const ros::SteadyTimerEvent&);
  bool robotPose(double* x, double* y, double* yaw);
  bool clearService(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  void diagnoseCostmap(diagnostic_updater::DiagnosticStatusWrapper& status);
  void applyFootprint();
  /// Replaces the entries of `keys` and adds `errors` (by key) to the config errors.
  void setErrors(const ConfigErrorLog& errors, const std::vector<std::string>& keys);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  CostmapRosConfig config_;
  std::mutex errors_mutex_;
  ConfigErrorLog config_errors_;             ///< by key: a later valid value clears its entry
  std::vector<std::string> param_warnings_;  ///< wrong types, unknown / unsupported keys (start-up)
  std::vector<std::string> layer_types_;     ///< the loaded layers' types as configured

  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  // The loader must outlive the plugin instances it created: declared first, destroyed last.
  std::unique_ptr<pluginlib::ClassLoader<Layer>> plugin_loader_;
  std::unique_ptr<LayeredCostmap> layered_costmap_;
  std::unique_ptr<CostmapPublisher> publisher_;
  ros::Publisher footprint_publisher_;
  geometry_msgs::PolygonStamped footprint_msg_;  ///< the padded footprint in robot_base_frame
  ros::ServiceServer clear_service_;
  diagnostic_updater::Updater diagnostics_;
  ReconfigureHost<CostmapConfig> reconfigure_;
  bool reconfigure_started_ = false;

  ros::Timer update_timer_;
  ros::SteadyTimer clock_watch_;
  std::mutex update_mutex_;  ///< one update at a time even on a multi-threaded queue
  std::size_t updates_skipped_busy_ = 0;
  DataUpdateTrigger data_trigger_;  ///< update_on_data: updates right after new data
  std::size_t data_updates_ = 0;
  std::mutex data_stamp_mutex_;
  ros::Time oldest_unpublished_stamp_;  ///< of data integrated since the last publish (0: none)
  SampleWindow data_to_publish_ms_;     ///< stamp -> publish of the oldest data in a message
  double data_to_publish_max_ms_ = 0.0;
  CellBounds unpublished_;  ///< cells redrawn since the last publish
  ros::Time last_publish_;
  ClockJumpDetector clock_jump_;
  ros::Time last_update_;
  TimingStats update_time_ms_;
  RunningStats update_period_s_;
  std::size_t updates_ = 0;
  std::size_t clears_ = 0;
  std::size_t robot_pose_failures_ = 0;
  std::string last_pose_error_;
};

}  // namespace downstream_perception
