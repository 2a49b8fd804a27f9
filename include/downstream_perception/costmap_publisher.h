// Publishes a Costmap as nav_msgs/OccupancyGrid with costmap_2d's value translation
// (0 -> 0, 1..252 -> 1..98, 253 -> 99, 254 -> 100, 255 -> -1), so rviz's "costmap" colour scheme
// and every costmap_2d consumer read it unchanged.
#pragma once

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <string>

#include "downstream_perception/core/costmap.h"

namespace downstream_perception {

class CostmapPublisher {
 public:
  CostmapPublisher(ros::NodeHandle& nh, const std::string& topic, std::string frame_id);
  void publish(const Costmap& costmap, const ros::Time& stamp);
  static void toMessage(const Costmap& costmap, const std::string& frame_id, const ros::Time& stamp,
                        nav_msgs::OccupancyGrid* msg);

 private:
  ros::Publisher publisher_;
  std::string frame_id_;
};

}  // namespace downstream_perception
