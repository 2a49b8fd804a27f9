// Nodelet shell around HandoffRos ("downstream_perception/HandoffNodelet").
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "downstream_perception/ros/handoff/handoff_ros.h"

namespace downstream_perception {

class HandoffNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    handoff_ = std::make_unique<HandoffRos>(getNodeHandle(), getPrivateNodeHandle());
  }
  std::unique_ptr<HandoffRos> handoff_;
};

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::HandoffNodelet, nodelet::Nodelet)
