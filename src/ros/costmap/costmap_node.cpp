// Stand-alone node: the same CostmapRos the nodelet hosts.
#include <ros/ros.h>

#include "downstream_perception/ros/costmap/costmap_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "costmap");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  downstream_perception::CostmapRos costmap(nh, pnh);
  ros::AsyncSpinner spinner(2);  // scans keep flowing while an update runs
  spinner.start();
  ros::waitForShutdown();
  return 0;
}
