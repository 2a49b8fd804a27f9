#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

void Layer::initialize(LayeredCostmap* parent, const std::string& name, tf2_ros::Buffer* tf,
                       const ros::NodeHandle& host_private_nh, const ros::NodeHandle& host_nh) {
  layered_costmap_ = parent;
  name_ = name;
  tf_ = tf;
  nh_ = ros::NodeHandle(host_private_nh, name);
  topic_nh_ = host_nh;
  onInitialize();
}

void Layer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.summary(diagnostic_msgs::DiagnosticStatus::OK, enabled_ ? "enabled" : "disabled");
}

}  // namespace downstream_perception
