// Nodelet shell around TrackerRos ("downstream_perception/TrackerNodelet").
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "downstream_perception/ros/tracking/tracker_ros.h"

namespace downstream_perception {

class TrackerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    tracker_ = std::make_unique<TrackerRos>(getNodeHandle(), getPrivateNodeHandle());
  }
  std::unique_ptr<TrackerRos> tracker_;
};

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::TrackerNodelet, nodelet::Nodelet)
