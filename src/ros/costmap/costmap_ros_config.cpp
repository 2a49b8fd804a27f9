#include "downstream_perception/ros/costmap/costmap_ros_config.h"

#include <ros/console.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/ros/common/config_errors.h"

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

CostmapRosConfig readCostmapConfig(ParamReader& params, ConfigErrorLog* errors) {
  CostmapRosConfig c;
  params.get("global_frame", &c.global_frame);
  params.get("robot_base_frame", &c.robot_base_frame);
  params.get("update_frequency", &c.update_frequency);
  params.get("publish_frequency", &c.publish_frequency);
  params.get("width", &c.width);
  params.get("height", &c.height);
  params.get("resolution", &c.resolution);
  params.get("origin_x", &c.origin_x);
  params.get("origin_y", &c.origin_y);
  params.get("transform_tolerance", &c.transform_tolerance);
  params.get("track_unknown_space", &c.track_unknown_space);
  params.get("rolling_window", &c.rolling_window);
  params.get("always_send_full_costmap", &c.always_send_full_costmap);
  params.get("update_on_data", &c.update_on_data);
  params.get("update_on_data_max_rate_hz", &c.update_on_data_max_rate_hz);
  validateCostmapConfig(&c, CostmapRosConfig(), errors);
  return c;
}

const std::vector<std::string>& costmapConfigKeys() {
  static const std::vector<std::string> keys{"global_frame",
                                             "robot_base_frame",
                                             "update_frequency",
                                             "publish_frequency",
                                             "width",
                                             "height",
                                             "resolution",
                                             "origin_x",
                                             "origin_y",
                                             "transform_tolerance",
                                             "track_unknown_space",
                                             "rolling_window",
                                             "always_send_full_costmap",
                                             "update_on_data",
                                             "update_on_data_max_rate_hz"};
  return keys;
}

void validateCostmapConfig(CostmapRosConfig* c, const CostmapRosConfig& fallback,
                           ConfigErrorLog* errors) {
  for (const char* key : {"update_frequency", "publish_frequency", "transform_tolerance",
                          "update_on_data_max_rate_hz", "width/height/resolution/origin"}) {
    errors->clearWithPrefix(key);
  }
  const auto reject = [errors](const std::string& name, const std::string& value,
                               const std::string& used) {
    const std::string msg = "parameter ~" + name + " = " + value + " is invalid; using " + used;
    ROS_ERROR("costmap: %s", msg.c_str());
    errors->keep(name, msg);
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
  if (!std::isfinite(c->update_on_data_max_rate_hz) || c->update_on_data_max_rate_hz <= 0.0 ||
      c->update_on_data_max_rate_hz > 1000.0) {
    reject("update_on_data_max_rate_hz", toText(c->update_on_data_max_rate_hz),
           toText(fallback.update_on_data_max_rate_hz));
    c->update_on_data_max_rate_hz = fallback.update_on_data_max_rate_hz;
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
