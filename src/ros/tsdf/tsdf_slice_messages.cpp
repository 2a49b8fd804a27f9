#include "downstream_perception/ros/tsdf/tsdf_slice_messages.h"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <cstdint>

#include "downstream_perception/ros/common/conversions.h"

namespace downstream_perception {

nav_msgs::OccupancyGridPtr sliceGridMessage(const std::vector<SliceCell>& cells,
                                            const GridGeometry& grid, double z_m,
                                            const std_msgs::Header& header) {
  nav_msgs::OccupancyGridPtr msg(new nav_msgs::OccupancyGrid);
  msg->header = header;
  msg->info = mapMetaData(grid, z_m, header.stamp);
  msg->data.resize(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    msg->data[i] = cells[i] == SliceCell::kOccupied ? 100 : (cells[i] == SliceCell::kFree ? 0 : -1);
  }
  return msg;
}

sensor_msgs::PointCloud2Ptr sliceDistanceCloud(const std::vector<float>& distance,
                                               const GridGeometry& grid, double z_m,
                                               const std_msgs::Header& header) {
  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2Fields(
      4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "distance", 1, sensor_msgs::PointField::FLOAT32);
  std::size_t known = 0;
  for (const float d : distance) known += std::isfinite(d);
  modifier.resize(known);
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z"),
      d(*cloud, "distance");
  for (int cy = 0; cy < grid.sizeY(); ++cy) {
    for (int cx = 0; cx < grid.sizeX(); ++cx) {
      const float value = distance[grid.index(cx, cy)];
      if (!std::isfinite(value)) continue;
      *x = static_cast<float>(grid.originX() + (cx + 0.5) * grid.resolution());
      *y = static_cast<float>(grid.originY() + (cy + 0.5) * grid.resolution());
      *z = static_cast<float>(z_m);
      *d = value;
      ++x, ++y, ++z, ++d;
    }
  }
  return cloud;
}

}  // namespace downstream_perception
