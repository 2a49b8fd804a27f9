#include "downstream_perception/layers/observation/laser_scan_source.h"

#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace downstream_perception {

namespace {
// A horizontal scanner may be tilted by a few degrees; beyond this a 2-D layer would smear it.
constexpr double kMaxTiltRad = 10.0 * M_PI / 180.0;
}  // namespace

LaserScanSource::LaserScanSource(std::string name, const ObservationSourceConfig& config,
                                 ros::NodeHandle nh, tf2_ros::Buffer& tf, std::string global_frame,
                                 Callback on_observation)
    : ObservationSource(std::move(name), config, nh, tf, std::move(global_frame),
                        std::move(on_observation)) {}

void LaserScanSource::subscribe() {
  if (subscription_.subscribed()) return;  // activate() runs at every reconfigure
  subscription_.subscribe(
      nh_, config_.topic, tf_, global_frame_, config_.tf_queue_size,
      [this](const sensor_msgs::LaserScanConstPtr& msg) { onScan(msg); },
      [this](const sensor_msgs::LaserScanConstPtr& msg,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onTfFailure(msg->header.frame_id, msg->header.stamp, reason);
      });
  subscription_.setTolerance(tolerance_);
  markSubscribed();
}

bool LaserScanSource::sensorPose(const std::string& frame, const ros::Time& stamp,
                                 bool reject_on_failure, Pose2D* pose, bool* upside_down,
                                 ScanHeightModel* heights) {
  geometry_msgs::TransformStamped t;
  if (!lookup(frame, stamp, &t, reject_on_failure)) return false;
  const Eigen::Matrix3d r = rotationOf(t.transform.rotation);
  // The scan plane's normal must be (anti)parallel to the global z axis.
  if (std::abs(r(2, 2)) < std::cos(kMaxTiltRad)) {
    std::ostringstream s;
    s << "sensor frame '" << frame << "' is tilted "
      << std::acos(std::min(1.0, std::abs(r(2, 2)))) * 180.0 / M_PI
      << " deg from horizontal (limit " << kMaxTiltRad * 180.0 / M_PI << " deg)";
    reject("bad pose: sensor tilted", s.str());
    return false;
  }
  pose->x = t.transform.translation.x;
  pose->y = t.transform.translation.y;
  pose->yaw = std::atan2(r(1, 0), r(0, 0));
  *upside_down = r(2, 2) < 0.0;
  if (heights != nullptr) {
    heights->origin_z = t.transform.translation.z;
    heights->zx = r(2, 0);
    heights->zy = r(2, 1);
  }
  return true;
}

void LaserScanSource::onScan(const sensor_msgs::LaserScanConstPtr& msg) {
  countReceived();
  if (msg->header.stamp.isZero()) {
    // tf reads stamp 0 as "latest": that is exactly the mistake we exist to prevent.
    reject("bad message: zero stamp", "a scan must carry its measurement time");
    return;
  }
  const std::string why = checkScan(*msg);
  if (!why.empty()) {
    reject("bad message: inconsistent scan", why);
    return;
  }

  const std::string& frame = frameOf(msg->header.frame_id);
  Pose2D first;
  bool upside_down = false;
  ScanHeightModel heights;
  if (!sensorPose(frame, msg->header.stamp, true, &first, &upside_down, &heights)) return;
  // costmap_2d's rules on a copy of the ranges: the height band (every beam's end, global z) and
  // its inf_is_valid substitution. Beams set to NaN here are counted as outside the band.
  ranges_.assign(msg->ranges.begin(), msg->ranges.end());
  const CloudBeamsConfig band = heightBand();
  const ScanPrefilterStats filtered = prefilterScanRanges(
      &ranges_, msg->angle_min, msg->angle_increment, msg->range_max,
      config_.costmap2d_inf_is_valid,
      std::min<double>(msg->range_max, config_.integrator.raytrace_max_range), heights,
      ScanHeightBand{band.min_obstacle_height, band.max_obstacle_height});
  LaserScanView view{ranges_.data(),       ranges_.size(), msg->angle_min,
                     msg->angle_increment, msg->range_min, msg->range_max};
  if (upside_down) {
    // Upside-down scanner: beam angles run clockwise in the global frame.
    view.angle_min = -view.angle_min;
    view.angle_increment = -view.angle_increment;
  }

  Observation obs;
  obs.stamp = msg->header.stamp;
  // REP: the header stamp is the first beam's time; beam k is taken k * time_increment later.
  const double sweep_s = msg->time_increment * static_cast<double>(msg->ranges.size() - 1);
  bool corrected = false;
  if (config_.per_beam_time_correction && sweep_s != 0.0 && msg->ranges.size() > 1) {
    if (sweep_s > tolerance_.toSec()) {
      tolerance_ = ros::Duration(sweep_s);  // from now on wait for tf at the last beam too
      subscription_.setTolerance(tolerance_);
    }
    Pose2D last;
    bool last_upside_down = false;
    if (sensorPose(frame, msg->header.stamp + ros::Duration(sweep_s), false, &last,
                   &last_upside_down) &&
        last_upside_down == upside_down) {
      integrator_.beamsFromMovingScan(view, first, last, &obs.beams, &obs.decisions);
      corrected = true;
    } else {
      note("per-beam correction skipped (no tf at the last beam's time)");
    }
  }
  if (!corrected) integrator_.beamsFromScan(view, first, &obs.beams, &obs.decisions);
  obs.decisions.beams_invalid -= std::min(obs.decisions.beams_invalid, filtered.outside_band);
  obs.decisions.points_outside_height += filtered.outside_band;
  on_observation_(*this, obs);
}

}  // namespace downstream_perception
