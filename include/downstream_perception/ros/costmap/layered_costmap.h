// The master grid plus the ordered list of Layer plugins that draw into it.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <ros/time.h>

#include "downstream_perception/core/costmap/footprint.h"
#include "downstream_perception/core/grid/costmap.h"
#include "downstream_perception/ros/costmap/layer.h"

namespace downstream_perception {

class LayeredCostmap {
 public:
  LayeredCostmap(std::string global_frame, bool track_unknown_space);

  /// Resizes the master (every cell to the default value) and calls matchSize() on each layer.
  void resizeMap(const GridGeometry& geometry);
  /// A layer (the static map) asks the master to take `geometry` and keep it: the size is then
  /// locked (a reconfigure of width / height / resolution / origin no longer resizes), as
  /// costmap_2d's resizeMap(..., size_locked = true). Resizes (under mutex(), calling every
  /// layer's matchSize()) only if the geometry differs. A host that owns another master (the
  /// costmap_2d adapter) installs a handler that resizes that one instead. Call it without
  /// holding a layer's own lock: the resize calls back into every layer.
  void lockSizeTo(const GridGeometry& geometry);
  /// Whether a layer has fixed the master's geometry (see lockSizeTo()).
  bool sizeLocked() const { return size_locked_; }
  void setSizeLockHandler(std::function<void(const GridGeometry&)> handler) {
    size_lock_handler_ = std::move(handler);
  }
  void addPlugin(std::shared_ptr<Layer> plugin) { plugins_.push_back(std::move(plugin)); }
  const std::vector<std::shared_ptr<Layer>>& plugins() const { return plugins_; }

  /// One update. With a rolling window and a robot pose, first re-centres the map on the robot by
  /// whole cells (master and layers shift; that update redraws everything). Then: union of the
  /// enabled layers' bounds, reset of that window in the master, each enabled layer's
  /// updateCosts() in order. `have_robot_pose` false means x, y, yaw are not known (tf missing):
  /// no shift, and layers that need the pose (footprint clearing) skip it. Returns the window
  /// that was redrawn.
  CellBounds updateMap(double robot_x, double robot_y, double robot_yaw,
                       bool have_robot_pose = true);
  /// Whether the pose passed to the current / last updateMap() was known.
  bool hasRobotPose() const { return have_robot_pose_; }
  /// The next updateMap() redraws the whole master (a layer was enabled or disabled, cleared).
  void requestFullRedraw() { full_redraw_ = true; }
  /// Returns and clears a pending full-redraw request (hosts that run their own update loop,
  /// such as the costmap_2d adapter).
  bool takeFullRedrawRequest() { return full_redraw_.exchange(false); }
  /// For hosts that run their own update loop: whether the robot pose of this update is known.
  void setHaveRobotPose(bool known) { have_robot_pose_ = known; }
  void setRollingWindow(bool rolling) { rolling_window_ = rolling; }
  bool isRolling() const { return rolling_window_; }
  /// Resets the master and every layer.
  void resetLayers();
  /// Tells every layer that the ROS clock went back.
  void onClockJump();

  /// Called by a layer once it has integrated new data stamped `stamp` (a scan, a cloud, a track
  /// array, a slice) that changes its output: the host measures how long data waits to be
  /// published, and its update_on_data mode updates and publishes right after. Cheap; any
  /// thread. Without a handler (the costmap_2d adapter's shadow) it does nothing.
  void notifyDataArrived(const ros::Time& stamp);
  /// The host's reaction to notifyDataArrived() (empty: none). Clear it before the host goes
  /// away: layers may notify from their subscriber threads until they are destroyed.
  void setDataHandler(std::function<void(const ros::Time&)> handler);

  Costmap& costmap() { return master_; }
  const Costmap& costmap() const { return master_; }
  /// Held by updateMap(); take it to read the master consistently from another thread.
  std::recursive_mutex& mutex() { return mutex_; }
  const std::string& globalFrame() const { return global_frame_; }
  bool isTrackingUnknown() const { return track_unknown_space_; }
  /// AND over the enabled layers.
  bool isCurrent() const;

  /// Sets the (padded) footprint, computes its radii and tells every layer.
  void setFootprint(const Footprint& footprint);
  const Footprint& footprint() const { return footprint_; }
  double inscribedRadius() const { return inscribed_radius_; }          ///< m
  double circumscribedRadius() const { return circumscribed_radius_; }  ///< m

 private:
  std::string global_frame_;
  bool track_unknown_space_;
  Costmap master_;
  std::vector<std::shared_ptr<Layer>> plugins_;
  std::recursive_mutex mutex_;
  Footprint footprint_;
  double inscribed_radius_ = 0.0;
  double circumscribed_radius_ = 0.0;
  bool rolling_window_ = false;
  bool have_robot_pose_ = false;
  std::atomic<bool> full_redraw_{false};
  std::atomic<bool> size_locked_{false};
  std::function<void(const GridGeometry&)> size_lock_handler_;
  std::mutex data_handler_mutex_;
  std::function<void(const ros::Time&)> data_handler_;
};

}  // namespace downstream_perception
