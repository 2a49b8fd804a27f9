#include "downstream_perception/ros/costmap/costmap_publisher.h"

#include "downstream_perception/ros/common/conversions.h"

namespace downstream_perception {

CostmapPublisher::CostmapPublisher(ros::NodeHandle& nh, const std::string& topic,
                                   std::string frame_id, bool always_send_full)
    : frame_id_(std::move(frame_id)), always_send_full_(always_send_full) {
  // Not latched: a latched topic would hand a late subscriber the last full grid published,
  // however old. Each new subscriber gets the current grid at once instead (costmap_2d's
  // onNewSubscription), and the next message is a full grid, so that it also matches the updates
  // that follow whatever order the two topics arrive in.
  full_publisher_ = nh.advertise<nav_msgs::OccupancyGrid>(
      topic, 1, [this](const ros::SingleSubscriberPublisher& subscriber) {
        need_full_ = true;
        sendCurrent(subscriber);
      });
  update_publisher_ = nh.advertise<map_msgs::OccupancyGridUpdate>(topic + "_updates", 10);
}

void CostmapPublisher::setNewSubscriberSource(GridSource source) {
  std::lock_guard<std::mutex> lock(source_mutex_);
  new_subscriber_source_ = std::move(source);
}

void CostmapPublisher::sendCurrent(const ros::SingleSubscriberPublisher& subscriber) {
  std::lock_guard<std::mutex> lock(source_mutex_);
  if (!new_subscriber_source_) return;
  nav_msgs::OccupancyGrid msg;
  new_subscriber_source_(&msg);
  subscriber.publish(msg);
}

void CostmapPublisher::toMessage(const Costmap& costmap, const std::string& frame_id,
                                 const ros::Time& stamp, nav_msgs::OccupancyGrid* msg) {
  static constexpr auto kTable = cost::occupancyTable();
  const GridGeometry& g = costmap.geometry();
  msg->header.frame_id = frame_id;
  msg->header.stamp = stamp;
  msg->info = mapMetaData(g, 0.0, stamp);
  msg->data.resize(g.cellCount());
  const std::uint8_t* src = costmap.data();
  for (std::size_t i = 0; i < g.cellCount(); ++i) msg->data[i] = kTable[src[i]];
}

void CostmapPublisher::toUpdateMessage(const Costmap& costmap, const CellBounds& window,
                                       const std::string& frame_id, const ros::Time& stamp,
                                       map_msgs::OccupancyGridUpdate* msg) {
  static constexpr auto kTable = cost::occupancyTable();
  const CellBounds w = costmap.clamp(window);
  msg->header.frame_id = frame_id;
  msg->header.stamp = stamp;
  if (w.empty()) {
    msg->x = msg->y = msg->width = msg->height = 0;
    msg->data.clear();
    return;
  }
  const int width = w.max_x - w.min_x + 1;
  const int height = w.max_y - w.min_y + 1;
  msg->x = w.min_x;
  msg->y = w.min_y;
  msg->width = static_cast<std::uint32_t>(width);
  msg->height = static_cast<std::uint32_t>(height);
  msg->data.resize(static_cast<std::size_t>(width) * height);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* src = costmap.data() + costmap.geometry().index(w.min_x, w.min_y + y);
    std::int8_t* dst = msg->data.data() + static_cast<std::size_t>(y) * width;
    for (int x = 0; x < width; ++x) dst[x] = kTable[src[x]];
  }
}

void CostmapPublisher::publish(const Costmap& costmap, const ros::Time& stamp,
                               const CellBounds& changed) {
  if (need_full_ || always_send_full_ || costmap.geometry() != last_geometry_) {
    nav_msgs::OccupancyGridPtr msg(new nav_msgs::OccupancyGrid);
    toMessage(costmap, frame_id_, stamp, msg.get());
    full_publisher_.publish(msg);
    last_geometry_ = costmap.geometry();
    need_full_ = false;
    ++full_published_;
    return;
  }
  if (costmap.clamp(changed).empty()) return;
  map_msgs::OccupancyGridUpdatePtr msg(new map_msgs::OccupancyGridUpdate);
  toUpdateMessage(costmap, changed, frame_id_, stamp, msg.get());
  update_publisher_.publish(msg);
  ++updates_published_;
}

}  // namespace downstream_perception
