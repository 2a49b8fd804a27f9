// Stand-alone node: the same HandoffRos the nodelet hosts.
#include <ros/ros.h>

#include "downstream_perception/ros/handoff/handoff_ros.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "handoff");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  downstream_perception::HandoffRos handoff(nh, pnh);
  ros::spin();
  return 0;
}
