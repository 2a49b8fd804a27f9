#include "downstream_perception/ros/costmap/layered_costmap.h"

#include <cmath>
#include <limits>
#include <utility>

namespace downstream_perception {

LayeredCostmap::LayeredCostmap(std::string global_frame, bool track_unknown_space)
    : global_frame_(std::move(global_frame)), track_unknown_space_(track_unknown_space) {
  master_.setDefaultValue(track_unknown_space ? cost::kNoInformation : cost::kFreeSpace);
}

void LayeredCostmap::resizeMap(const GridGeometry& geometry) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  master_.resize(geometry);
  for (auto& plugin : plugins_) plugin->matchSize();
  full_redraw_ = true;
}

void LayeredCostmap::lockSizeTo(const GridGeometry& geometry) {
  if (size_lock_handler_) {
    size_lock_handler_(geometry);  // takes its master's lock first, then ours (via matchSize)
    return;
  }
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  size_locked_ = true;
  if (master_.geometry() != geometry) resizeMap(geometry);
}

CellBounds LayeredCostmap::updateMap(double robot_x, double robot_y, double robot_yaw,
                                     bool have_robot_pose) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  have_robot_pose_ = have_robot_pose;
  if (rolling_window_ && have_robot_pose) {
    // Robot-centred, snapped to whole cells so that cell contents never get resampled. The rule
    // is costmap_2d's (LayeredCostmap::updateMap + Costmap2D::updateOrigin), quirks included:
    // its size in metres is (cells - 0.5) * resolution and the shift truncates toward zero, so
    // a rolling window here lies on the same cells as costmap_2d's for the same robot poses.
    const GridGeometry& g = master_.geometry();
    const double res = g.resolution();
    const double new_origin_x = robot_x - (g.sizeX() - 0.5) * res / 2.0;
    const double new_origin_y = robot_y - (g.sizeY() - 0.5) * res / 2.0;
    const int dx = static_cast<int>((new_origin_x - g.originX()) / res);
    const int dy = static_cast<int>((new_origin_y - g.originY()) / res);
    if (dx != 0 || dy != 0) {
      master_.shift(dx, dy);
      for (auto& plugin : plugins_) plugin->shiftOrigin(dx, dy);
      full_redraw_ = true;
    }
  }
  double min_x = std::numeric_limits<double>::max();
  double min_y = std::numeric_limits<double>::max();
  double max_x = std::numeric_limits<double>::lowest();
  double max_y = std::numeric_limits<double>::lowest();
  for (auto& plugin : plugins_) {
    if (!plugin->isEnabled()) continue;
    plugin->updateBounds(robot_x, robot_y, robot_yaw, &min_x, &min_y, &max_x, &max_y);
  }
  CellBounds window = master_.geometry().worldBoxToCells(min_x, min_y, max_x, max_y);
  if (full_redraw_.exchange(false)) {
    window = CellBounds{};
    window.expand(0, 0);
    window.expand(master_.geometry().sizeX() - 1, master_.geometry().sizeY() - 1);
  }
  if (window.empty()) return window;
  master_.resetWindow(window);
  for (auto& plugin : plugins_) {
    if (!plugin->isEnabled()) continue;
    plugin->updateCosts(master_, window.min_x, window.min_y, window.max_x + 1, window.max_y + 1);
  }
  return window;
}

void LayeredCostmap::resetLayers() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  master_.reset();
  for (auto& plugin : plugins_) plugin->reset();
  full_redraw_ = true;
}

void LayeredCostmap::onClockJump() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  for (auto& plugin : plugins_) plugin->onClockJump();
}

bool LayeredCostmap::isCurrent() const {
  for (const auto& plugin : plugins_) {
    if (plugin->isEnabled() && !plugin->isCurrent()) return false;
  }
  return true;
}

void LayeredCostmap::setFootprint(const Footprint& footprint) {
  footprint_ = footprint;
  inscribed_radius_ = downstream_perception::inscribedRadius(footprint);
  circumscribed_radius_ = downstream_perception::circumscribedRadius(footprint);
  for (const auto& plugin : plugins_) plugin->onFootprintChanged();
}

void LayeredCostmap::notifyDataArrived(const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(data_handler_mutex_);
  if (data_handler_) data_handler_(stamp);
}

void LayeredCostmap::setDataHandler(std::function<void(const ros::Time&)> handler) {
  std::lock_guard<std::mutex> lock(data_handler_mutex_);
  data_handler_ = std::move(handler);
}

}  // namespace downstream_perception
