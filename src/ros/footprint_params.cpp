#include "downstream_perception/footprint_params.h"

#include <ros/console.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cmath>
#include <sstream>

namespace downstream_perception {

namespace {

constexpr double kDefaultRobotRadius = 0.46;  // m, costmap_2d's default
constexpr double kDefaultPadding = 0.01;      // m, costmap_2d's default

double asDouble(const XmlRpc::XmlRpcValue& v) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
  return std::nan("");
}

// "[[x, y], [x, y], ...]" -> points; empty on a parse error.
Footprint parseString(const std::string& text) {
  std::string cleaned;
  for (const char c : text) cleaned += (c == '[' || c == ']' || c == ',') ? ' ' : c;
  std::istringstream in(cleaned);
  std::vector<double> values;
  double v = 0.0;
  while (in >> v) values.push_back(v);
  if (!in.eof() || values.size() % 2 != 0) return {};
  Footprint polygon;
  for (std::size_t i = 0; i + 1 < values.size(); i += 2)
    polygon.push_back({values[i], values[i + 1]});
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
  Footprint polygon;
  XmlRpc::XmlRpcValue raw;
  if (pnh.getParam("footprint", raw)) {
    if (raw.getType() == XmlRpc::XmlRpcValue::TypeString) {
      polygon = parseString(static_cast<std::string>(raw));
    } else if (raw.getType() == XmlRpc::XmlRpcValue::TypeArray) {
      for (int i = 0; i < raw.size(); ++i) {
        if (raw[i].getType() != XmlRpc::XmlRpcValue::TypeArray || raw[i].size() != 2) {
          polygon.clear();
          break;
        }
        polygon.push_back({asDouble(raw[i][0]), asDouble(raw[i][1])});
      }
    }
    const std::string why = validateFootprint(polygon);
    if (why.empty()) return padFootprint(polygon, padding);
    report(errors, "parameter ~footprint is invalid (" + why +
                       "); expected [[x, y], ...] with >= 3 points; using ~robot_radius");
  }
  double radius = kDefaultRobotRadius;
  pnh.param("robot_radius", radius, kDefaultRobotRadius);
  if (!std::isfinite(radius) || radius < 0.0 || radius > 100.0) {
    report(errors, "parameter ~robot_radius is invalid; using 0.46 m");
    radius = kDefaultRobotRadius;
  }
  return padFootprint(circularFootprint(radius), padding);
}

}  // namespace downstream_perception
