// Base class of every costmap layer plugin (pluginlib base "downstream_perception::Layer").
//
// The lifecycle follows costmap_2d::Layer so that porting a layer is mechanical:
//   initialize() -> onInitialize(); per update: updateBounds() (may only grow the box), then
//   updateCosts() into the master window [min_i, max_i) x [min_j, max_j); matchSize() after every
//   master resize; reset(), activate()/deactivate(), onFootprintChanged(); isCurrent().
// Differences: initialize() also takes the host's private NodeHandle (the layer's parameters live
// in <host private ns>/<name>), updateCosts() takes our ROS-free Costmap, and every layer reports
// its own health through diagnose().
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>
#include <ros/node_handle.h>

#include <string>

#include "downstream_perception/core/grid/costmap.h"

namespace tf2_ros {
class Buffer;
}

namespace downstream_perception {

class LayeredCostmap;

class Layer {
 public:
  virtual ~Layer() = default;

  /// `host_nh`: the host node's own namespace, where relative topics resolve (costmap_2d's
  /// layers subscribe through the node's global NodeHandle: `topic: scan` of a costmap in
  /// move_base is /scan, not /move_base/local_costmap/obstacles/scan).
  void initialize(LayeredCostmap* parent, const std::string& name, tf2_ros::Buffer* tf,
                  const ros::NodeHandle& host_private_nh,
                  const ros::NodeHandle& host_nh = ros::NodeHandle());

  /// World-metre box that this layer needs redrawn; only grow the box.
  virtual void updateBounds(double robot_x, double robot_y, double robot_yaw, double* min_x,
                            double* min_y, double* max_x, double* max_y) {
    (void)robot_x, (void)robot_y, (void)robot_yaw, (void)min_x, (void)min_y, (void)max_x,
        (void)max_y;
  }
  /// Writes this layer's contribution into the master inside [min_i, max_i) x [min_j, max_j).
  virtual void updateCosts(Costmap& master, int min_i, int min_j, int max_i, int max_j) {
    (void)master, (void)min_i, (void)min_j, (void)max_i, (void)max_j;
  }
  /// The master's size, resolution or origin changed.
  virtual void matchSize() {}
  /// Rolling window: the master's origin moved by (dx, dy) whole cells and its content moved
  /// with it. Layers keep what stays in view; the default forgets everything (matchSize()).
  virtual void shiftOrigin(int dx, int dy) {
    (void)dx, (void)dy;
    matchSize();
  }
  /// Forget everything (clear services, move_base's clear_costmaps).
  virtual void reset() {}
  virtual void activate() {}
  virtual void deactivate() {}
  virtual void onFootprintChanged() {}
  /// The ROS clock went back (a looped bag, a restarted simulator): forget stamps and clocks
  /// kept from the old timeline (the map itself stays).
  virtual void onClockJump() {}
  /// Fills a diagnostics status (summary level + key/values). Called at the diagnostics rate.
  virtual void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  /// False while the layer's inputs are missing or stale.
  bool isCurrent() const { return current_; }
  /// "" while current, else why not (for the host's WARN): a layer with inputs names them.
  virtual std::string notCurrentReason() const {
    return current_ ? std::string() : "layer '" + name_ + "' is not current";
  }
  bool isEnabled() const { return enabled_; }
  const std::string& name() const { return name_; }

 protected:
  virtual void onInitialize() {}

  LayeredCostmap* layered_costmap_ = nullptr;
  std::string name_;
  tf2_ros::Buffer* tf_ = nullptr;
  ros::NodeHandle nh_;        ///< the layer's parameter namespace: <host private ns>/<name>
  ros::NodeHandle topic_nh_;  ///< the host node's namespace: sensor topics resolve here
  bool current_ = true;
  bool enabled_ = true;
};

}  // namespace downstream_perception
