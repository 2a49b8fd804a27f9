#include "downstream_perception/costmap_publisher.h"

namespace downstream_perception {

CostmapPublisher::CostmapPublisher(ros::NodeHandle& nh, const std::string& topic,
                                   std::string frame_id)
    : frame_id_(std::move(frame_id)) {
  // Latched: rviz and late subscribers get the current map at once.
  publisher_ = nh.advertise<nav_msgs::OccupancyGrid>(topic, 1, true);
}

void CostmapPublisher::toMessage(const Costmap& costmap, const std::string& frame_id,
                                 const ros::Time& stamp, nav_msgs::OccupancyGrid* msg) {
  static constexpr auto kTable = cost::occupancyTable();
  const GridGeometry& g = costmap.geometry();
  msg->header.frame_id = frame_id;
  msg->header.stamp = stamp;
  msg->info.map_load_time = stamp;
  msg->info.resolution = static_cast<float>(g.resolution());
  msg->info.width = static_cast<std::uint32_t>(g.sizeX());
  msg->info.height = static_cast<std::uint32_t>(g.sizeY());
  msg->info.origin.position.x = g.originX();
  msg->info.origin.position.y = g.originY();
  msg->info.origin.position.z = 0.0;
  msg->info.origin.orientation.w = 1.0;
  msg->data.resize(g.cellCount());
  const std::uint8_t* src = costmap.data();
  for (std::size_t i = 0; i < g.cellCount(); ++i) msg->data[i] = kTable[src[i]];
}

void CostmapPublisher::publish(const Costmap& costmap, const ros::Time& stamp) {
  nav_msgs::OccupancyGridPtr msg(new nav_msgs::OccupancyGrid);
  toMessage(costmap, frame_id_, stamp, msg.get());
  publisher_.publish(msg);
}

}  // namespace downstream_perception
