// Structural checks of incoming sensor messages, shared by the obstacle layer's sources and the
// handoff nodelet: each returns an empty string when the message can be used, else the reason
// (for the log line and the diagnostics count). Stamps are checked by the callers.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace downstream_perception {

/// Ranges present, finite non-zero angle increment spanning at most a turn, angle_max agreeing
/// with the beam count, a valid range interval, finite time_increment, intensities empty or one
/// per range.
std::string checkScan(const sensor_msgs::LaserScan& msg);

/// x, y, z consecutive little-endian FLOAT32 fields, and point_step, row_step and the data size
/// agreeing with width and height. *x_offset (if given) receives the x field's offset.
std::string checkCloudLayout(const sensor_msgs::PointCloud2& msg, std::size_t* x_offset = nullptr);

/// A finite resolution > 0 and width x height (in 64 bits) equal to the data size.
std::string checkOccupancyGrid(const nav_msgs::OccupancyGrid& msg);

/// False with a reason for a depth image the TSDF cannot read: an encoding other than 32FC1 /
/// 16UC1, a byte order other than the host's, or an inconsistent size.
bool checkDepthImage(const sensor_msgs::Image& image, std::string* why);

/// A depth image as metres (32FC1 as is, 16UC1 millimetres converted, 0 -> NaN), after
/// checkDepthImage() (false with its reason). With zero_is_no_return, a 16UC1 0 becomes +Inf
/// (REP 118's no return) instead: drivers that write 0 for "too far" (a 32FC1 0 stays 0, which
/// the consumers read as a no-return under the same setting).
bool depthImageToMetres(const sensor_msgs::Image& image, std::vector<float>* metres,
                        std::string* why, bool zero_is_no_return = false);

/// Calls visit(x, y, z) (floats, NaN passed on) for each point of a cloud that passed
/// checkCloudLayout, which gave x_offset. Reads through the checked row_step and point_step only,
/// so no field offset of the message can take it outside the data.
template <class Visitor>
void forEachCloudPoint(const sensor_msgs::PointCloud2& msg, std::size_t x_offset, Visitor&& visit) {
  if (msg.width == 0) return;  // an empty cloud may still claim 2^32 - 1 rows of nothing
  for (std::size_t row = 0; row < msg.height; ++row) {
    const std::uint8_t* p = msg.data.data() + row * msg.row_step + x_offset;
    for (std::size_t k = 0; k < msg.width; ++k, p += msg.point_step) {
      float xyz[3];
      std::memcpy(xyz, p, sizeof(xyz));  // PointCloud2 data need not be aligned
      visit(xyz[0], xyz[1], xyz[2]);
    }
  }
}

/// The cloud with its rows packed (row_step = width * point_step), for code that walks a cloud
/// as one run of points (PointCloud2Iterator, tf2::doTransform): with padded rows such a walk
/// steps over the end of the data. Returns the message itself when already packed.
sensor_msgs::PointCloud2ConstPtr packedCloud(const sensor_msgs::PointCloud2ConstPtr& msg);

/// A frame, a finite position within 1e8 m and a finite unit quaternion (|q| within 1 %: rounding
/// in a hand-written goal is forgiven, a zero quaternion is not).
std::string checkPose(const geometry_msgs::PoseStamped& msg);

}  // namespace downstream_perception
