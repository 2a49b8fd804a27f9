// rviz markers for tracks: a box at the object's size, its id, a velocity arrow and the 2-sigma
// covariance ellipse, each with a stable ns/id per track, and DELETE for tracks that died.
#pragma once

#include <visualization_msgs/MarkerArray.h>

#include <cstdint>
#include <set>
#include <string>

#include "downstream_perception/TrackedObjectArray.h"

namespace downstream_perception {

class TrackMarkers {
 public:
  /// Markers for `tracks` plus DELETE markers for the ids published last time and gone now.
  visualization_msgs::MarkerArray build(const TrackedObjectArray& tracks);

 private:
  std::set<std::uint64_t> shown_;
};

}  // namespace downstream_perception
