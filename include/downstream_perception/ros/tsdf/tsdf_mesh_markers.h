// The TSDF mesh as rviz markers: one TRIANGLE_LIST per block (ns "tsdf_mesh"), so a mesh update
// republishes only the blocks the mesher re-extracted and DELETEs the blocks that are gone.
// Vertices are coloured by their normal (x, y, z -> r, g, b), which shows the shape without
// lighting.
#pragma once

#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdint>

#include "downstream_perception/core/tsdf/marching_cubes.h"

namespace downstream_perception {

class TsdfMeshMarkers {
 public:
  /// Markers for the blocks extracted by the mesher's last update (ADD, or DELETE when empty)
  /// and for the blocks published before that no longer exist (DELETE).
  visualization_msgs::MarkerArray changed(const TsdfMesher& mesher, const std_msgs::Header& header);
  /// DELETEALL for the namespace (after ~clear).
  visualization_msgs::MarkerArray clearAll(const std_msgs::Header& header);

 private:
  int idOf(const Eigen::Vector3i& block);
  tsl::robin_map<Eigen::Vector3i, int, BlockIndexHash> ids_;
  int next_id_ = 0;
};

}  // namespace downstream_perception
