// The TSDF's height-band slice as ROS messages: the slice itself as an OccupancyGrid (what the
// TsdfLayer draws into a costmap) and its clearance (the Euclidean distance to the nearest
// occupied cell) as a PointCloud2 that rviz colours by distance, like voxblox's ESDF slice.
#pragma once

#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>

#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"

namespace downstream_perception {

/// The slice over `grid` at height z_m: 100 occupied, 0 free, -1 unknown.
nav_msgs::OccupancyGridPtr sliceGridMessage(const std::vector<SliceCell>& cells,
                                            const GridGeometry& grid, double z_m,
                                            const std_msgs::Header& header);

/// One point (x, y, z, distance: float32, m) per cell centre with a finite distance (the known
/// cells of sliceDistance's output), at height z_m.
sensor_msgs::PointCloud2Ptr sliceDistanceCloud(const std::vector<float>& distance,
                                               const GridGeometry& grid, double z_m,
                                               const std_msgs::Header& header);

}  // namespace downstream_perception
