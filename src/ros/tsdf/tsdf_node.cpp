// Stand-alone node: the same TsdfRos the nodelet hosts.
#include <ros/ros.h>

#include "downstream_perception/ros/tsdf/tsdf_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tsdf");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  downstream_perception::TsdfRos tsdf(nh, pnh);
  ros::spin();
  return 0;
}
