// Fuzz driver for the nodelets' message checks (make fuzz; not built by make build).
//
// Reads cases from stdin, each a header line "<kind> <bytes>\n" followed by a ROS-serialized
// message (kind: scan, cloud, pose, depth), runs the check the nodelets run on that message and,
// when the check accepts it, what the consumers do next with it. Answers one line per case:
//   accept                    the check accepted and every consumer step stayed in bounds
//   reject <reason>           the check refused the message (a clean refusal)
//   garbage <what>            the check accepted a message its consumers cannot read safely
//   exception <what>          a consumer step threw (in a roscpp callback: the node dies)
//   harness <what>            the case itself was malformed (a bug of the harness)
// A crash or a hang is seen by the harness (test/fuzz/fuzz.py) as the process dying or going quiet.
// No ROS master is needed: messages are only deserialized and checked.
#include <geometry_msgs/TransformStamped.h>
#include <ros/serialization.h>
#include <ros/time.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_sensor_msgs/tf2_sensor_msgs.h>
#include <boost/make_shared.hpp>

#include <cmath>
#include <cstdint>
#include <exception>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/cloud_beams.h"
#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/tsdf/tsdf_ros.h"

namespace dp = downstream_perception;

namespace {

/// A case the harness framed wrongly (not a finding about the checks).
struct BadCase : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <class M>
M deserialize(std::vector<std::uint8_t>& bytes) {
  M msg;
  ros::serialization::IStream stream(bytes.data(), static_cast<std::uint32_t>(bytes.size()));
  try {
    ros::serialization::deserialize(stream, msg);
  } catch (const std::exception& e) {
    throw BadCase(std::string("cannot deserialize: ") + e.what());
  }
  if (stream.getLength() != 0) throw BadCase("trailing bytes after the message");
  return msg;
}

/// LaserScanSource and PlanningFrameRelay after checkScan: beams from the scan (the layer's
/// integrator) and the sweep time as a ros::Duration (both consumers build one from it).
std::string scanConsumers(const sensor_msgs::LaserScan& msg) {
  const dp::LaserScanView view{msg.ranges.data(),   msg.ranges.size(), msg.angle_min,
                               msg.angle_increment, msg.range_min,     msg.range_max};
  dp::ScanIntegrator integrator;
  std::vector<dp::BeamUpdate> beams;
  dp::IntegrationStats stats;
  integrator.beamsFromScan(view, dp::Pose2D{}, &beams, &stats);
  const double sweep_s = msg.time_increment * (static_cast<double>(msg.ranges.size()) - 1.0);
  const ros::Duration sweep(std::max(0.0, sweep_s));  // throws out of range
  (void)sweep;
  return {};
}

/// Whether a PointCloud2 iterator over `field` (tf2::doTransform's loop: one
/// point per point_step over the whole data) reads only inside the data. Checks the addresses
/// the real iterator yields, without reading through them.
std::string iteratorStaysInside(const sensor_msgs::PointCloud2& msg, const char* field) {
  const std::uint8_t* begin = msg.data.data();
  const std::uint8_t* end = begin + msg.data.size();
  std::size_t steps = 0;
  for (sensor_msgs::PointCloud2ConstIterator<float> it(msg, field); it != it.end(); ++it) {
    const auto* at = reinterpret_cast<const std::uint8_t*>(&*it);
    if (at < begin || at + sizeof(float) > end) {
      std::ostringstream why;
      why << "iterator over '" << field << "' reads bytes " << (at - begin) << ".."
          << (at - begin + 4) << " of " << msg.data.size() << " (point " << steps << ")";
      return why.str();
    }
    if (++steps > msg.data.size()) return std::string("iterator over '") + field + "' never ends";
  }
  return {};
}

/// PointCloudSource, the TSDF and the handoff relay after checkCloudLayout.
std::string cloudConsumers(const sensor_msgs::PointCloud2& msg, std::size_t x_offset) {
  // PointCloudSource: width points per row, point_step apart, from row * row_step + x_offset.
  if (msg.width > 0 && msg.height > 0) {
    const std::uint64_t last =
        static_cast<std::uint64_t>(msg.height - 1) * msg.row_step + x_offset +
        static_cast<std::uint64_t>(msg.width - 1) * msg.point_step + 3 * sizeof(float);
    if (last > msg.data.size()) {
      return "obstacle layer reads up to byte " + std::to_string(last) + " of " +
             std::to_string(msg.data.size());
    }
  }
  dp::ScanIntegrator integrator;
  std::vector<dp::BeamUpdate> beams;
  dp::IntegrationStats stats;
  const std::uint32_t rows = msg.width == 0 ? 0 : msg.height;  // as PointCloudSource::onCloud
  for (std::uint32_t row = 0; row < rows; ++row) {
    dp::beamsFromCloud(integrator, dp::CloudBeamsConfig{},
                       msg.data.data() + static_cast<std::size_t>(row) * msg.row_step + x_offset,
                       msg.width, msg.point_step, Eigen::Isometry3d::Identity(), &beams, &stats);
  }
  // The TSDF: forEachCloudPoint through the checked steps.
  std::uint64_t points = 0;
  dp::forEachCloudPoint(msg, x_offset, [&points](float, float, float) { ++points; });
  if (points != static_cast<std::uint64_t>(msg.width) * (msg.width == 0 ? 0 : msg.height)) {
    return "TSDF: forEachCloudPoint visited " + std::to_string(points) + " points";
  }
  // The relay: tf2::doTransform (a PointCloud2 iterator per point_step over the whole data) on
  // the packed cloud.
  const sensor_msgs::PointCloud2ConstPtr packed =
      dp::packedCloud(boost::make_shared<sensor_msgs::PointCloud2>(msg));
  for (const char* field : {"x", "y", "z"}) {
    const std::string why = iteratorStaysInside(*packed, field);
    if (!why.empty()) return "relay: " + why;
  }
  geometry_msgs::TransformStamped identity;
  identity.transform.rotation.w = 1.0;
  sensor_msgs::PointCloud2 out;
  tf2::doTransform(*packed, out, identity);
  return {};
}

/// The TSDF after checkDepthImage: the conversion to metres.
std::string depthConsumers(const sensor_msgs::Image& msg) {
  std::vector<float> metres;
  std::string why;
  if (!dp::depthImageToMetres(msg, &metres, &why)) return "depthImageToMetres refused: " + why;
  if (metres.size() != static_cast<std::size_t>(msg.width) * msg.height) {
    return "depthImageToMetres gave " + std::to_string(metres.size()) + " depths";
  }
  return {};
}

/// One case: "accept", "reject <why>", "garbage <why>" or "exception <what>".
std::string runCase(const std::string& kind, std::vector<std::uint8_t>& bytes) {
  std::string why;
  std::string broken;
  if (kind == "scan") {
    const auto msg = deserialize<sensor_msgs::LaserScan>(bytes);
    why = dp::checkScan(msg);
    if (why.empty()) broken = scanConsumers(msg);
  } else if (kind == "cloud") {
    const auto msg = deserialize<sensor_msgs::PointCloud2>(bytes);
    std::size_t x_offset = 0;
    why = dp::checkCloudLayout(msg, &x_offset);
    if (why.empty()) broken = cloudConsumers(msg, x_offset);
  } else if (kind == "pose") {
    const auto msg = deserialize<geometry_msgs::PoseStamped>(bytes);
    why = dp::checkPose(msg);
  } else if (kind == "depth") {
    const auto msg = deserialize<sensor_msgs::Image>(bytes);
    if (dp::checkDepthImage(msg, &why)) broken = depthConsumers(msg);
  } else {
    throw BadCase("unknown kind '" + kind + "'");
  }
  if (!why.empty()) return "reject " + why;
  if (!broken.empty()) return "garbage " + broken;
  return "accept";
}

std::string oneLine(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

}  // namespace

int main() {
  ros::Time::init();  // ros::Duration/Time arithmetic without a node
  std::ios::sync_with_stdio(false);
  std::string header;
  while (std::getline(std::cin, header)) {
    std::istringstream fields(header);
    std::string kind;
    std::size_t size = 0;
    if (!(fields >> kind >> size)) {
      std::cerr << "fuzz_message_checks: bad header '" << header << "'\n";
      return 2;
    }
    std::vector<std::uint8_t> bytes(size);
    if (!std::cin.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size))) {
      std::cerr << "fuzz_message_checks: short read\n";
      return 2;
    }
    std::string answer;
    try {
      answer = runCase(kind, bytes);
    } catch (const BadCase& e) {
      answer = std::string("harness ") + e.what();
    } catch (const std::exception& e) {
      answer = std::string("exception ") + e.what();
    }
    std::cout << oneLine(answer) << std::endl;
  }
  return 0;
}
