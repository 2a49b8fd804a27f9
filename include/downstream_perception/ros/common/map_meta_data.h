// The nav_msgs/MapMetaData of a GridGeometry: shared by every OccupancyGrid the package
// publishes (the costmap, the TSDF slice), so they agree on how a grid is described.
#pragma once

#include <nav_msgs/MapMetaData.h>
#include <ros/time.h>

#include <cstdint>

#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

/// Size, resolution and origin (corner of cell (0, 0), at height z_m, not rotated) of `grid`.
inline nav_msgs::MapMetaData mapMetaData(const GridGeometry& grid, double z_m,
                                         const ros::Time& load_time) {
  nav_msgs::MapMetaData info;
  info.map_load_time = load_time;
  info.resolution = static_cast<float>(grid.resolution());
  info.width = static_cast<std::uint32_t>(grid.sizeX());
  info.height = static_cast<std::uint32_t>(grid.sizeY());
  info.origin.position.x = grid.originX();
  info.origin.position.y = grid.originY();
  info.origin.position.z = z_m;
  info.origin.orientation.w = 1.0;
  return info;
}

}  // namespace downstream_perception
