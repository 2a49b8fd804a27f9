// ROS host of a LayeredCostmap: parameters, plugin loading, the update timer, publishing and
// diagnostics. The nodelet and the node are thin shells around this class.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <pluginlib/class_loader.hpp>

#include <memory>
#include <mutex>
#include <string>

#include "downstream_perception/costmap_publisher.h"
#include "downstream_perception/layered_costmap.h"
#include "downstream_perception/running_stats.h"

namespace downstream_perception {

struct CostmapRosConfig {
  std::string global_frame = "map";
  std::string robot_base_frame = "base_link";
  double update_frequency = 5.0;     ///< Hz
  double publish_frequency = 1.0;    ///< Hz; 0 = never publish
  double width = 10.0;               ///< m
  double height = 10.0;              ///< m
  double resolution = 0.05;          ///< m / cell
  double origin_x = 0.0;             ///< m, lower-left corner in global_frame
  double origin_y = 0.0;             ///< m
  double transform_tolerance = 0.3;  ///< s: oldest acceptable robot pose
  bool track_unknown_space = true;
};

class CostmapRos {
 public:
  CostmapRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~CostmapRos();

  LayeredCostmap& layeredCostmap() { return *layered_costmap_; }

 private:
  void readConfig();
  void loadPlugins();
  void updateTimerCallback(const ros::TimerEvent& event);
  bool robotPose(double* x, double* y, double* yaw);
  void diagnoseCostmap(diagnostic_updater::DiagnosticStatusWrapper& status);
  void publishFootprint();

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  CostmapRosConfig config_;
  std::vector<std::string> config_errors_;

  std::shared_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  // The loader must outlive the plugin instances it created: declared first, destroyed last.
  std::unique_ptr<pluginlib::ClassLoader<Layer>> plugin_loader_;
  std::unique_ptr<LayeredCostmap> layered_costmap_;
  std::unique_ptr<CostmapPublisher> publisher_;
  ros::Publisher footprint_publisher_;
  diagnostic_updater::Updater diagnostics_;

  ros::Timer update_timer_;
  std::mutex update_mutex_;  ///< one update at a time even on a multi-threaded queue
  std::size_t updates_skipped_busy_ = 0;
  ros::Time last_publish_;
  ros::Time last_update_;
  RunningStats update_time_ms_;
  RunningStats update_period_s_;
  std::size_t updates_ = 0;
  std::size_t robot_pose_failures_ = 0;
  std::string last_pose_error_;
};

}  // namespace downstream_perception
