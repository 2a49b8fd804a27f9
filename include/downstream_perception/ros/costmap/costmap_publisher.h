// Publishes a Costmap as nav_msgs/OccupancyGrid on <topic> and, between full grids, the changed
// window as map_msgs/OccupancyGridUpdate on <topic>_updates (costmap_2d's protocol, which rviz's
// Map display and every costmap_2d client understand). Values use costmap_2d's translation
// (0 -> 0, 1..252 -> 1..98, 253 -> 99, 254 -> 100, 255 -> -1).
#pragma once

#include <map_msgs/OccupancyGridUpdate.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

#include "downstream_perception/core/grid/costmap.h"

namespace downstream_perception {

class CostmapPublisher {
 public:
  CostmapPublisher(ros::NodeHandle& nh, const std::string& topic, std::string frame_id,
                   bool always_send_full);

  /// The whole grid when it is the first message, the size or origin changed, a full grid was
  /// requested or always_send_full is set; else the window `changed` (inclusive, clamped) as an
  /// update, or nothing if it is empty.
  void publish(const Costmap& costmap, const ros::Time& stamp, const CellBounds& changed);
  void setAlwaysSendFull(bool always) { always_send_full_ = always; }
  /// Fills the current grid for a new subscriber of <topic>.
  using GridSource = std::function<void(nav_msgs::OccupancyGrid*)>;
  /// When set, each new subscriber of <topic> gets the grid `source` fills at once, sent to it
  /// alone: costmap_2d's Costmap2DPublisher::onNewSubscription, which is how a costmap with
  /// publish_frequency 0 (Fetch's global costmap) still reaches rviz or a planner.
  void setNewSubscriberSource(GridSource source);
  /// The next publish() sends the whole grid.
  void requestFull() { need_full_ = true; }

  std::size_t fullGridsPublished() const { return full_published_; }
  std::size_t updatesPublished() const { return updates_published_; }

  static void toMessage(const Costmap& costmap, const std::string& frame_id, const ros::Time& stamp,
                        nav_msgs::OccupancyGrid* msg);
  static void toUpdateMessage(const Costmap& costmap, const CellBounds& window,
                              const std::string& frame_id, const ros::Time& stamp,
                              map_msgs::OccupancyGridUpdate* msg);

 private:
  void sendCurrent(const ros::SingleSubscriberPublisher& subscriber);

  ros::Publisher full_publisher_;
  ros::Publisher update_publisher_;
  std::string frame_id_;
  bool always_send_full_;
  std::atomic<bool> need_full_{true};
  GridGeometry last_geometry_;
  std::size_t full_published_ = 0;
  std::size_t updates_published_ = 0;
  std::mutex source_mutex_;
  GridSource new_subscriber_source_;
};

}  // namespace downstream_perception
