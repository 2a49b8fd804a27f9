// Structural checks of incoming sensor messages, shared by the obstacle layer's sources and the
// handoff nodelet: each returns an empty string when the message can be used, else the reason
// (for the log line and the diagnostics count). Stamps are checked by the callers.
#pragma once

#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>

#include <cstddef>
#include <string>

namespace downstream_perception {

/// Ranges present, finite non-zero angle increment spanning at most a turn, angle_max agreeing
/// with the beam count, a valid range interval, finite time_increment, intensities empty or one
/// per range.
std::string checkScan(const sensor_msgs::LaserScan& msg);

/// x, y, z consecutive little-endian FLOAT32 fields, and point_step, row_step and the data size
/// agreeing with width and height. *x_offset (if given) receives the x field's offset.
std::string checkCloudLayout(const sensor_msgs::PointCloud2& msg, std::size_t* x_offset = nullptr);

/// A frame, a finite position and a finite unit quaternion (|q| within 1 %: rounding in a
/// hand-written goal is forgiven, a zero quaternion is not).
std::string checkPose(const geometry_msgs::PoseStamped& msg);

}  // namespace downstream_perception
