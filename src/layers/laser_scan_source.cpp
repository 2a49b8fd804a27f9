#include "downstream_perception/layers/laser_scan_source.h"

#include <geometry_msgs/TransformStamped.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>

#include <cmath>
#include <sstream>

namespace downstream_perception {

namespace {
const char* reasonName(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "tf: older than the transform cache";
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "tf: empty frame_id";
    default:
      return "tf: no transform in time (queue overflow: unknown frame or late tf)";
  }
}
// A horizontal scanner may be tilted by a few degrees; beyond this a 2-D layer would smear it.
constexpr double kMaxTiltRad = 10.0 * M_PI / 180.0;
}  // namespace

LaserScanSource::LaserScanSource(std::string name, const LaserScanSourceConfig& config,
                                 ros::NodeHandle nh, tf2_ros::Buffer& tf, std::string global_frame,
                                 Callback on_scan)
    : name_(std::move(name)),
      config_(config),
      nh_(nh),
      tf_(tf),
      global_frame_(std::move(global_frame)),
      on_scan_(std::move(on_scan)),
      integrator_(config.integrator) {
  if (config_.topic.empty()) config_.topic = name_;
}

LaserScanSource::~LaserScanSource() {
  unsubscribe();
}

void LaserScanSource::subscribe() {
  if (subscriber_) return;
  subscriber_ =
      std::make_unique<message_filters::Subscriber<sensor_msgs::LaserScan>>(nh_, config_.topic, 50);
  filter_ = std::make_unique<tf2_ros::MessageFilter<sensor_msgs::LaserScan>>(
      *subscriber_, tf_, global_frame_, static_cast<std::uint32_t>(config_.tf_queue_size), nh_);
  filter_->registerCallback(boost::bind(&LaserScanSource::onScan, this, boost::placeholders::_1));
  filter_->registerFailureCallback(boost::bind(&LaserScanSource::onTfFailure, this,
                                               boost::placeholders::_1, boost::placeholders::_2));
}

void LaserScanSource::unsubscribe() {
  if (subscriber_) subscriber_->unsubscribe();
  filter_.reset();
  subscriber_.reset();
}

void LaserScanSource::reject(const std::string& reason, const std::string& detail) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++health_.rejected[reason];
  }
  ROS_WARN_THROTTLE(2.0, "obstacle source '%s' (%s): scan rejected: %s: %s", name_.c_str(),
                    config_.topic.c_str(), reason.c_str(), detail.c_str());
}

void LaserScanSource::onTfFailure(const sensor_msgs::LaserScanConstPtr& msg,
                                  tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++health_.received;
  }
  std::ostringstream detail;
  detail << "frame '" << msg->header.frame_id << "' -> '" << global_frame_ << "' at stamp "
         << msg->header.stamp;
  reject(reasonName(reason), detail.str());
}

void LaserScanSource::onScan(const sensor_msgs::LaserScanConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++health_.received;
    health_.last_received = ros::WallTime::now();
  }
  if (msg->header.stamp.isZero()) {
    // tf reads stamp 0 as "latest": that is exactly the mistake we exist to prevent.
    reject("bad message: zero stamp", "a scan must carry its measurement time");
    return;
  }
  AcceptedScan scan;
  scan.msg = msg;
  scan.view = LaserScanView{msg->ranges.data(),   msg->ranges.size(), msg->angle_min,
                            msg->angle_increment, msg->range_min,     msg->range_max};
  std::string why = scan.view.validate();
  if (why.empty() && std::isfinite(msg->angle_max)) {
    const double expected = (msg->angle_max - msg->angle_min) / msg->angle_increment + 1.0;
    if (std::abs(expected - static_cast<double>(msg->ranges.size())) > 1.5) {
      std::ostringstream s;
      s << msg->ranges.size() << " ranges but angle_min/max/increment imply " << expected;
      why = s.str();
    }
  }
  if (!why.empty()) {
    reject("bad message: inconsistent scan", why);
    return;
  }

  const std::string& frame =
      config_.sensor_frame.empty() ? msg->header.frame_id : config_.sensor_frame;
  geometry_msgs::TransformStamped t;
  try {
    t = tf_.lookupTransform(global_frame_, frame, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    reject("tf: lookup at stamp failed", e.what());
    return;
  }
  const auto& q = t.transform.rotation;
  const tf2::Matrix3x3 r(tf2::Quaternion(q.x, q.y, q.z, q.w));
  // The scan plane's normal must be (anti)parallel to the global z axis.
  if (std::abs(r[2][2]) < std::cos(kMaxTiltRad)) {
    std::ostringstream s;
    s << "sensor frame '" << frame << "' is tilted "
      << std::acos(std::min(1.0, std::abs(r[2][2]))) * 180.0 / M_PI
      << " deg from horizontal (limit " << kMaxTiltRad * 180.0 / M_PI << " deg)";
    reject("bad pose: sensor tilted", s.str());
    return;
  }
  scan.sensor_pose.x = t.transform.translation.x;
  scan.sensor_pose.y = t.transform.translation.y;
  scan.sensor_pose.yaw = std::atan2(r[1][0], r[0][0]);
  if (r[2][2] < 0.0) {
    // Upside-down scanner: beam angles run clockwise in the global frame.
    scan.view.angle_min = -scan.view.angle_min;
    scan.view.angle_increment = -scan.view.angle_increment;
  }
  on_scan_(*this, scan);
}

void LaserScanSource::recordIntegration(const IntegrationStats& stats, double integrate_ms,
                                        double age_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++health_.integrated;
  health_.last = stats;
  health_.total.accumulate(stats);
  health_.integrate_ms.add(integrate_ms);
  health_.transform_age_s.add(age_s);
}

bool LaserScanSource::isCurrent() const {
  if (config_.expected_update_rate <= 0.0) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  if (health_.integrated == 0) return false;
  return (ros::WallTime::now() - health_.last_received).toSec() <= config_.expected_update_rate;
}

}  // namespace downstream_perception
