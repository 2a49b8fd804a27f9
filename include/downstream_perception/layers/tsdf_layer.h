// TSDF layer: the TSDF nodelet's height-band slice (nav_msgs/OccupancyGrid on ~topic) drawn into
// the costmap as LETHAL cells, so 3-D obstacles a 2-D lidar misses (a table top, an overhang
// within the robot's height) reach the planner. The TSDF does the 3-D work (in the same nodelet
// manager the grid arrives without a copy); this layer only maps its cells onto the master.
#pragma once

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <mutex>
#include <string>
#include <vector>

#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class TsdfLayer : public Layer {
 public:
  void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x, double* min_y,
                    double* max_x, double* max_y) override;
  void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) override;
  void reset() override;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) override;

 protected:
  void onInitialize() override;

 private:
  void onSlice(const nav_msgs::OccupancyGridConstPtr& msg);

  std::mutex mutex_;
  ros::Subscriber subscriber_;
  std::string topic_;
  std::string global_frame_;
  double max_age_s_ = 0.0;
  nav_msgs::OccupancyGridConstPtr slice_;
  bool slice_changed_ = false;
  double drawn_min_x_ = 0.0, drawn_min_y_ = 0.0, drawn_max_x_ = -1.0, drawn_max_y_ = -1.0;
  std::size_t slices_received_ = 0;
  std::size_t slices_rejected_ = 0;
  std::string last_rejection_;
  std::size_t lethal_written_ = 0;
  ConfigErrorLog config_errors_;
  std::vector<std::string> param_warnings_;  ///< wrong types, unknown keys (start-up)
};

}  // namespace downstream_perception
