#include "downstream_perception/message_checks.h"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "downstream_perception/core/scan_integrator.h"

namespace downstream_perception {

std::string checkScan(const sensor_msgs::LaserScan& msg) {
  const LaserScanView view{msg.ranges.data(),   msg.ranges.size(), msg.angle_min,
                           msg.angle_increment, msg.range_min,     msg.range_max};
  std::string why = view.validate();
  if (!why.empty()) return why;
  if (std::isfinite(msg.angle_max)) {
    const double expected = (msg.angle_max - msg.angle_min) / msg.angle_increment + 1.0;
    if (std::abs(expected - static_cast<double>(msg.ranges.size())) > 1.5) {
      std::ostringstream s;
      s << msg.ranges.size() << " ranges but angle_min/max/increment imply " << expected;
      return s.str();
    }
  }
  if (!std::isfinite(msg.time_increment)) return "time_increment is not finite";
  if (!msg.intensities.empty() && msg.intensities.size() != msg.ranges.size()) {
    return std::to_string(msg.intensities.size()) + " intensities for " +
           std::to_string(msg.ranges.size()) + " ranges";
  }
  return {};
}

std::string checkCloudLayout(const sensor_msgs::PointCloud2& msg, std::size_t* x_offset) {
  const auto field = [&msg](const char* name) -> const sensor_msgs::PointField* {
    for (const auto& f : msg.fields) {
      if (f.name == name) return &f;
    }
    return nullptr;
  };
  const sensor_msgs::PointField* x = field("x");
  const sensor_msgs::PointField* y = field("y");
  const sensor_msgs::PointField* z = field("z");
  std::ostringstream why;
  if (x == nullptr || y == nullptr || z == nullptr) {
    why << "no x, y and z fields";
  } else if (x->datatype != sensor_msgs::PointField::FLOAT32 ||
             y->datatype != sensor_msgs::PointField::FLOAT32 ||
             z->datatype != sensor_msgs::PointField::FLOAT32 || y->offset != x->offset + 4 ||
             z->offset != x->offset + 8) {
    why << "x, y, z must be consecutive FLOAT32 fields";
  } else if (msg.is_bigendian) {
    why << "big-endian clouds are not supported";
  } else if (msg.point_step < x->offset + 12) {
    why << "point_step " << msg.point_step << " is smaller than the x, y, z fields";
  } else if (static_cast<std::uint64_t>(msg.width) * msg.point_step > msg.row_step) {
    why << "row_step " << msg.row_step << " < width * point_step";
  } else if (static_cast<std::uint64_t>(msg.row_step) * msg.height != msg.data.size()) {
    why << "data holds " << msg.data.size()
        << " bytes, row_step * height = " << static_cast<std::uint64_t>(msg.row_step) * msg.height;
  } else if (x_offset != nullptr) {
    *x_offset = x->offset;
  }
  return why.str();
}

std::string checkPose(const geometry_msgs::PoseStamped& msg) {
  if (msg.header.frame_id.empty()) return "empty frame_id";
  const auto& p = msg.pose.position;
  const auto& q = msg.pose.orientation;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    return "position is not finite";
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 0.01) {
    std::ostringstream s;
    s << "orientation is not a unit quaternion (|q| = " << norm << ")";
    return s.str();
  }
  return {};
}

}  // namespace downstream_perception
