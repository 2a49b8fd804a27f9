// Nodelet shell around CostmapRos ("downstream_perception/CostmapNodelet").
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "downstream_perception/ros/costmap/costmap_ros.h"

namespace downstream_perception {

class CostmapNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    costmap_ = std::make_unique<CostmapRos>(getMTNodeHandle(), getMTPrivateNodeHandle());
  }
  std::unique_ptr<CostmapRos> costmap_;
};

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::CostmapNodelet, nodelet::Nodelet)
