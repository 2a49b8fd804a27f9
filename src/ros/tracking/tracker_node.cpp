// Stand-alone node: the same TrackerRos the nodelet hosts.
#include <ros/ros.h>

#include "downstream_perception/ros/tracking/tracker_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tracker");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  downstream_perception::TrackerRos tracker(nh, pnh);
  ros::spin();
  return 0;
}
