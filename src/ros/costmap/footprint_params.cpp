#include "downstream_perception/ros/costmap/footprint_params.h"

#include <ros/console.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cmath>

namespace downstream_perception {

namespace {

constexpr double kDefaultRobotRadius = 0.46;  // m, costmap_2d's default
constexpr double kDefaultPadding = 0.01;      // m, costmap_2d's default

double asDouble(XmlRpc::XmlRpcValue& v) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
  return std::nan("");
}

// A list [[x, y], ...]: every element a pair of numbers, >= 3 of them (costmap_2d's rule).
Footprint parseList(XmlRpc::XmlRpcValue& raw, std::string* error) {
  Footprint polygon;
  if (raw.size() < 3) {
    *error = "a footprint needs at least 3 points, got " + std::to_string(raw.size());
    return {};
  }
  for (int i = 0; i < raw.size(); ++i) {
    if (raw[i].getType() != XmlRpc::XmlRpcValue::TypeArray || raw[i].size() != 2) {
      *error = "point " + std::to_string(i + 1) + " is not a pair [x, y]";
      return {};
    }
    const double x = asDouble(raw[i][0]);
    const double y = asDouble(raw[i][1]);
    if (std::isnan(x) || std::isnan(y)) {
      *error = "point " + std::to_string(i + 1) + " holds something other than numbers";
      return {};
    }
    polygon.push_back({x, y});
  }
  error->clear();
  return polygon;
}

void report(std::vector<std::string>* errors, const std::string& msg) {
  ROS_ERROR("costmap: %s", msg.c_str());
  errors->push_back(msg);
}

}  // namespace

Footprint readFootprint(const ros::NodeHandle& pnh, std::vector<std::string>* errors) {
  double padding = kDefaultPadding;
  pnh.param("footprint_padding", padding, kDefaultPadding);
  if (!std::isfinite(padding) || padding < 0.0 || padding > 10.0) {
    report(errors, "parameter ~footprint_padding is invalid; using 0.01 m");
    padding = kDefaultPadding;
  }
  // costmap_2d looks both keys up from the costmap's namespace upward: a move_base-level
  // footprint serves both costmaps.
  std::string key;
  XmlRpc::XmlRpcValue raw;
  if (pnh.searchParam("footprint", key) && pnh.getParam(key, raw)) {
    Footprint polygon;
    std::string why;
    const bool is_string = raw.getType() == XmlRpc::XmlRpcValue::TypeString;
    const std::string text = is_string ? static_cast<std::string>(raw) : std::string();
    if (is_string && (text.empty() || text == "[]")) {
      why = "";  // costmap_2d's "no polygon": the radius is used
    } else if (is_string) {
      polygon = parseFootprintString(text, &why);
    } else if (raw.getType() == XmlRpc::XmlRpcValue::TypeArray) {
      polygon = parseList(raw, &why);
    } else {
      why = "neither a list [[x, y], ...] nor a string";
    }
    if (why.empty() && !polygon.empty()) why = validateFootprint(polygon);
    if (why.empty() && !polygon.empty()) return padFootprint(polygon, padding);
    if (!why.empty())
      report(errors, "parameter " + key + " is invalid (" + why + "); using the robot radius");
  }
  double radius = kDefaultRobotRadius;
  if (pnh.searchParam("robot_radius", key)) pnh.param(key, radius, kDefaultRobotRadius);
  if (!std::isfinite(radius) || radius < 0.0 || radius > 100.0) {
    report(errors, "parameter robot_radius is invalid; using 0.46 m");
    radius = kDefaultRobotRadius;
  }
  return padFootprint(circularFootprint(radius), padding);
}

}  // namespace downstream_perception
