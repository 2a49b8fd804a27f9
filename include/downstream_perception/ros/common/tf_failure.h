// One wording for tf2 MessageFilter drops, shared by the nodes' "rejected (...)" diagnostics.
#pragma once

#include <tf2_ros/message_filter.h>

namespace downstream_perception {

inline const char* tfFailureReason(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "tf: older than the transform cache";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "tf: empty frame_id";
    default:
      return "tf: no transform in time (queue overflow: unknown frame or late tf)";
  }
}

}  // namespace downstream_perception
