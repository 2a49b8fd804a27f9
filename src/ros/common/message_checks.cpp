#include "downstream_perception/ros/common/message_checks.h"

#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace downstream_perception {

namespace {

bool hostIsBigEndian() {
  const std::uint16_t one = 1;
  std::uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

}  // namespace

std::string checkOccupancyGrid(const nav_msgs::OccupancyGrid& msg) {
  const auto& info = msg.info;
  if (!(std::isfinite(info.resolution) && info.resolution > 0.0f)) {
    return "resolution must be finite and > 0 m";
  }
  // 64 bits: width x height of two uint32 wraps around in 32 (65536 x 65536 is 0).
  const std::uint64_t cells = std::uint64_t{info.width} * std::uint64_t{info.height};
  if (cells != msg.data.size()) {
    std::ostringstream why;
    why << "data has " << msg.data.size() << " values, width x height = " << info.width << " x "
        << info.height;
    return why.str();
  }
  return "";
}

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
  // A sweep is a fraction of a second; ros::Duration throws beyond its 32-bit seconds.
  constexpr double kMaxSweepS = 10.0;
  if (!std::isfinite(msg.time_increment) ||
      std::abs(static_cast<double>(msg.time_increment)) * static_cast<double>(msg.ranges.size()) >
          kMaxSweepS) {
    return "time_increment " + std::to_string(msg.time_increment) + " s times " +
           std::to_string(msg.ranges.size()) + " beams is not a sweep of at most 10 s";
  }
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
  // Every size and offset below is a uint32 of the message: sums and products are taken in 64
  // bits so that no crafted value can wrap around and pass (an x offset of 2^32 - 8 plus 12).
  using U64 = std::uint64_t;
  std::ostringstream why;
  if (x == nullptr || y == nullptr || z == nullptr) {
    why << "no x, y and z fields";
  } else if (x->datatype != sensor_msgs::PointField::FLOAT32 ||
             y->datatype != sensor_msgs::PointField::FLOAT32 ||
             z->datatype != sensor_msgs::PointField::FLOAT32 || x->count == 0 || y->count == 0 ||
             z->count == 0 || U64{y->offset} != U64{x->offset} + 4 ||
             U64{z->offset} != U64{x->offset} + 8) {
    why << "x, y, z must be consecutive FLOAT32 fields";
  } else if (msg.is_bigendian) {
    why << "big-endian clouds are not supported";
  } else if (U64{msg.point_step} < U64{x->offset} + 12) {
    why << "point_step " << msg.point_step << " is smaller than the x, y, z fields (x at offset "
        << x->offset << ")";
  } else if (U64{msg.width} * msg.point_step > msg.row_step) {
    why << "row_step " << msg.row_step
        << " < width * point_step = " << U64{msg.width} * msg.point_step;
  } else if (U64{msg.row_step} * msg.height != msg.data.size()) {
    why << "data holds " << msg.data.size()
        << " bytes, row_step * height = " << U64{msg.row_step} * msg.height;
  } else if (x_offset != nullptr) {
    *x_offset = x->offset;
  }
  return why.str();
}

sensor_msgs::PointCloud2ConstPtr packedCloud(const sensor_msgs::PointCloud2ConstPtr& msg) {
  const std::size_t row_bytes = static_cast<std::size_t>(msg->width) * msg->point_step;
  if (msg->width == 0 || msg->height == 0) {
    sensor_msgs::PointCloud2Ptr empty(new sensor_msgs::PointCloud2(*msg));
    empty->width = empty->height = empty->row_step = 0;  // no rows of nothing
    empty->data.clear();
    return empty;
  }
  if (msg->row_step == row_bytes) return msg;
  sensor_msgs::PointCloud2Ptr packed(new sensor_msgs::PointCloud2);
  packed->header = msg->header;
  packed->height = msg->height;
  packed->width = msg->width;
  packed->fields = msg->fields;
  packed->is_bigendian = msg->is_bigendian;
  packed->point_step = msg->point_step;
  packed->row_step = static_cast<std::uint32_t>(row_bytes);
  packed->is_dense = msg->is_dense;
  packed->data.resize(row_bytes * msg->height);
  for (std::size_t row = 0; row < msg->height; ++row) {
    std::memcpy(packed->data.data() + row * row_bytes, msg->data.data() + row * msg->row_step,
                row_bytes);
  }
  return packed;
}

std::string checkPose(const geometry_msgs::PoseStamped& msg) {
  if (msg.header.frame_id.empty()) return "empty frame_id";
  const auto& p = msg.pose.position;
  const auto& q = msg.pose.orientation;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
    return "position is not finite";
  }
  // Beyond any map a robot plans in (UTM and ECEF coordinates stay far below): a garbage goal.
  constexpr double kMaxCoordinateM = 1e8;
  if (std::abs(p.x) > kMaxCoordinateM || std::abs(p.y) > kMaxCoordinateM ||
      std::abs(p.z) > kMaxCoordinateM) {
    return "position beyond 1e8 m";
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 0.01) {
    std::ostringstream s;
    s << "orientation is not a unit quaternion (|q| = " << norm << ")";
    return s.str();
  }
  return {};
}

bool checkDepthImage(const sensor_msgs::Image& image, std::string* why) {
  namespace enc = sensor_msgs::image_encodings;
  const bool is_float = image.encoding == enc::TYPE_32FC1;
  const bool is_mm = image.encoding == enc::TYPE_16UC1 || image.encoding == enc::MONO16;
  if (!is_float && !is_mm) {
    *why = "encoding '" + image.encoding + "' (need 32FC1 metres or 16UC1 millimetres)";
    return false;
  }
  if (static_cast<bool>(image.is_bigendian) != hostIsBigEndian()) {
    *why = "byte order differs from this machine's";
    return false;
  }
  const std::size_t pixel_bytes = is_float ? 4 : 2;
  if (image.width == 0 || image.height == 0 || image.step < image.width * pixel_bytes ||
      image.data.size() < static_cast<std::size_t>(image.step) * image.height) {
    *why = "size inconsistent (width " + std::to_string(image.width) + ", height " +
           std::to_string(image.height) + ", step " + std::to_string(image.step) + ", " +
           std::to_string(image.data.size()) + " bytes)";
    return false;
  }
  return true;
}

bool depthImageToMetres(const sensor_msgs::Image& image, std::vector<float>* metres,
                        std::string* why, bool zero_is_no_return) {
  if (!checkDepthImage(image, why)) return false;
  const bool is_float = image.encoding == sensor_msgs::image_encodings::TYPE_32FC1;
  metres->resize(static_cast<std::size_t>(image.width) * image.height);
  std::vector<std::uint16_t> mm(is_float ? 0 : image.width);  // one row, aligned
  for (std::uint32_t v = 0; v < image.height; ++v) {
    const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(v) * image.step;
    float* out = metres->data() + static_cast<std::size_t>(v) * image.width;
    if (is_float) {
      std::memcpy(out, row, image.width * sizeof(float));
    } else {
      std::memcpy(mm.data(), row, image.width * sizeof(std::uint16_t));
      millimetresToMetres(mm.data(), mm.size(), out);
      if (zero_is_no_return) {
        for (std::size_t u = 0; u < mm.size(); ++u) {
          if (mm[u] == 0) out[u] = std::numeric_limits<float>::infinity();
        }
      }
    }
  }
  return true;
}

}  // namespace downstream_perception
