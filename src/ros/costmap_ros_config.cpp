#include "downstream_perception/costmap_ros_config.h"

#include <ros/console.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "downstream_perception/config_errors.h"
#include "downstream_perception/core/grid_geometry.h"

namespace downstream_perception {

namespace {
int cells(double metres, double resolution) {
  return static_cast<int>(std::lround(std::min(metres / resolution, 1e9)));
}
}  // namespace

int CostmapRosConfig::sizeXCells() const {
  return cells(width, resolution);
}
int CostmapRosConfig::sizeYCells() const {
  return cells(height, resolution);
}

CostmapRosConfig readCostmapConfig(const ros::NodeHandle& pnh, std::vector<std::string>* errors) {
  const CostmapRosConfig d;
  CostmapRosConfig c;
  pnh.param("global_frame", c.global_frame, d.global_frame);
  pnh.param("robot_base_frame", c.robot_base_frame, d.robot_base_frame);
  pnh.param("update_frequency", c.update_frequency, d.update_frequency);
  pnh.param("publish_frequency", c.publish_frequency, d.publish_frequency);
  pnh.param("width", c.width, d.width);
  pnh.param("height", c.height, d.height);
  pnh.param("resolution", c.resolution, d.resolution);
  pnh.param("origin_x", c.origin_x, d.origin_x);
  pnh.param("origin_y", c.origin_y, d.origin_y);
  pnh.param("transform_tolerance", c.transform_tolerance, d.transform_tolerance);
  pnh.param("track_unknown_space", c.track_unknown_space, d.track_unknown_space);
  pnh.param("rolling_window", c.rolling_window, d.rolling_window);
  pnh.param("always_send_full_costmap", c.always_send_full_costmap, d.always_send_full_costmap);
  validateCostmapConfig(&c, d, errors);
  return c;
}

void validateCostmapConfig(CostmapRosConfig* c, const CostmapRosConfig& fallback,
                           std::vector<std::string>* errors) {
  const auto reject = [errors](const std::string& name, const std::string& value,
                               const std::string& used) {
    const std::string msg = "parameter ~" + name + " = " + value + " is invalid; using " + used;
    ROS_ERROR("costmap: %s", msg.c_str());
    errors->push_back(msg);
  };
  if (!std::isfinite(c->update_frequency) || c->update_frequency <= 0.0 ||
      c->update_frequency > 1000.0) {
    reject("update_frequency", toText(c->update_frequency), toText(fallback.update_frequency));
    c->update_frequency = fallback.update_frequency;
  }
  if (!std::isfinite(c->publish_frequency) || c->publish_frequency < 0.0) {
    reject("publish_frequency", toText(c->publish_frequency), toText(fallback.publish_frequency));
    c->publish_frequency = fallback.publish_frequency;
  }
  if (!std::isfinite(c->transform_tolerance) || c->transform_tolerance <= 0.0) {
    reject("transform_tolerance", toText(c->transform_tolerance),
           toText(fallback.transform_tolerance));
    c->transform_tolerance = fallback.transform_tolerance;
  }
  const std::string why =
      (std::isfinite(c->width) && std::isfinite(c->height) && c->resolution > 0.0)
          ? GridGeometry::validate(c->sizeXCells(), c->sizeYCells(), c->resolution, c->origin_x,
                                   c->origin_y)
          : std::string("width/height/resolution must be finite and positive");
  if (!why.empty()) {
    reject("width/height/resolution/origin",
           toText(c->width) + " x " + toText(c->height) + " m at " + toText(c->resolution) +
               " m (" + why + ")",
           toText(fallback.width) + " x " + toText(fallback.height) + " m at " +
               toText(fallback.resolution) + " m");
    c->width = fallback.width;
    c->height = fallback.height;
    c->resolution = fallback.resolution;
    c->origin_x = fallback.origin_x;
    c->origin_y = fallback.origin_y;
  }
}

}  // namespace downstream_perception
