// Nodelet shell around TsdfRos ("downstream_perception/TsdfNodelet").
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include <memory>

#include "downstream_perception/ros/tsdf/tsdf_ros.h"

namespace downstream_perception {

class TsdfNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    tsdf_ = std::make_unique<TsdfRos>(getNodeHandle(), getPrivateNodeHandle());
  }
  std::unique_ptr<TsdfRos> tsdf_;
};

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::TsdfNodelet, nodelet::Nodelet)
