#include "downstream_perception/ros/handoff/handoff_ros.h"

#include <tf2_geometry_msgs/tf2_geometry_msgs.h>  // PoseStamped in tf2_ros::Buffer::transform

#include <cmath>

#include "downstream_perception/core/grid/se2.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/common/param_reader.h"

namespace downstream_perception {

HandoffRos::HandoffRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_, nh), diagnostics_(nh, pnh, pnh.getNamespace()) {
  config_errors_.setPrefix("handoff");
  loadParameters();
  correction_ = CorrectionMonitor(correction_config_);
  health_.map_odom_pose_age_s = -1.0;  // no report yet
  RelayTopics topics;
  readParam(pnh_, "scan_topics", &topics.scans, &config_errors_);
  readParam(pnh_, "cloud_topics", &topics.clouds, &config_errors_);
  readParam(pnh_, "track_topics", &topics.tracks, &config_errors_);
  readParam(pnh_, "republish", &topics.republish, &config_errors_);
  readParam(pnh_, "tf_queue_size", &topics.tf_queue_size, &config_errors_);
  if (topics.tf_queue_size < 1 || topics.tf_queue_size > 10000) {
    config_errors_.add("parameter tf_queue_size = " + toText(topics.tf_queue_size) +
                       " must be in [1, 10000]; using 20");
    topics.tf_queue_size = 20;
  }
  relay_ = std::make_unique<PlanningFrameRelay>(nh_, pnh_, tf_buffer_, planning_frame_, topics);
  goal_publisher_ = pnh_.advertise<geometry_msgs::PoseStamped>("goal_base", 10);
  health_publisher_ = pnh_.advertise<SeamHealth>("seam_health", 1);
  goal_subscriber_ = nh_.subscribe("goal", 10, &HandoffRos::onGoal, this);
  transform_service_ = pnh_.advertiseService("transform_pose", &HandoffRos::onTransformPose, this);
  diagnostics_.setHardwareID("handoff");
  diagnostics_.add("seam", this, &HandoffRos::diagnose);
  // The server reads the YAML values (or the .cfg defaults, equal to SeamLimits') and calls
  // reconfigure() at once: one code path for start-up and live changes.
  reconfigure_.start(pnh_, this, &HandoffRos::reconfigure);
  timer_ = nh_.createTimer(ros::Duration(1.0 / health_rate_hz_), &HandoffRos::onTimer, this);
  ROS_INFO("handoff: planning in '%s', goals to '%s', %zu scan, %zu cloud and %zu track inputs%s",
           planning_frame_.c_str(), robot_base_frame_.c_str(), topics.scans.size(),
           topics.clouds.size(), topics.tracks.size(),
           topics.republish ? " re-published in the planning frame" : "");
}

void HandoffRos::loadParameters() {
  readParam(pnh_, "planning_frame", &planning_frame_, &config_errors_);
  readParam(pnh_, "odom_frame", &odom_frame_, &config_errors_);
  readParam(pnh_, "robot_base_frame", &robot_base_frame_, &config_errors_);
  readParam(pnh_, "health_rate_hz", &health_rate_hz_, &config_errors_);
  readParam(pnh_, "correction_window_s", &correction_config_.window_s, &config_errors_);
  readParam(pnh_, "correction_reset_drop_m", &correction_config_.reset_drop_m, &config_errors_);
  readParam(pnh_, "max_correction_m", &correction_config_.max_correction_m, &config_errors_);
  readParam(pnh_, "correction_min_travel_m", &correction_config_.min_travel_m, &config_errors_);
  if (!(std::isfinite(health_rate_hz_) && health_rate_hz_ > 0.0 && health_rate_hz_ <= 1000.0)) {
    config_errors_.add("parameter health_rate_hz = " + toText(health_rate_hz_) +
                       " must be in (0, 1000] Hz; using 2.0");
    health_rate_hz_ = 2.0;
  }
  const std::string why = correction_config_.validate();
  if (!why.empty()) {
    config_errors_.add(why + "; using the defaults");
    correction_config_ = CorrectionMonitorConfig();
  }
}

void HandoffRos::reconfigure(HandoffConfig& cfg, std::uint32_t) {
  SeamLimits proposed;
  proposed.reference_range_m = cfg.reference_range_m;
  proposed.max_transform_age_s = cfg.max_transform_age_s;
  proposed.max_smear_m = cfg.max_smear_m;
  proposed.max_map_odom_age_s = cfg.max_map_odom_age_s;
  std::vector<std::string> refused;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    limits_ = SeamLimits::acceptValid(proposed, limits_, &refused);
  }
  for (const std::string& why : refused) config_errors_.add(why);
}

bool HandoffRos::transformPose(const geometry_msgs::PoseStamped& in,
                               const std::string& target_frame, geometry_msgs::PoseStamped* out,
                               std::string* why) {
  const std::string& target = target_frame.empty() ? robot_base_frame_ : target_frame;
  try {
    // At the pose's own stamp (0 = latest), never silently "now".
    tf_buffer_.transform(in, *out, target, ros::Duration(0.2));
    return true;
  } catch (const tf2::TransformException& e) {
    *why = std::string("no transform '") + in.header.frame_id + "' -> '" + target +
           "' at the pose's stamp: " + e.what();
    return false;
  }
}

void HandoffRos::onGoal(const geometry_msgs::PoseStampedConstPtr& msg) {
  const std::string bad = checkPose(*msg);
  geometry_msgs::PoseStamped out;
  std::string why;
  if (!bad.empty() || !transformPose(*msg, robot_base_frame_, &out, &why)) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++(bad.empty() ? goal_failures_ : goals_rejected_);
    last_goal_failure_ = bad.empty() ? why : "bad goal: " + bad;
    ROS_WARN_THROTTLE(2.0, "handoff: goal dropped: %s", last_goal_failure_.c_str());
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++goals_;
  }
  goal_publisher_.publish(out);
}

bool HandoffRos::onTransformPose(TransformPose::Request& req, TransformPose::Response& res) {
  std::string why = checkPose(req.pose);
  res.success = why.empty() && transformPose(req.pose, req.target_frame, &res.pose, &why);
  res.message = res.success ? "ok" : why;
  return true;
}

void HandoffRos::onTimer(const ros::TimerEvent&) {
  // Yaw rate and travel from odom <- base_link: the latest transform and one 0.1 s older.
  double yaw_rate = 0.0;
  bool have_rate = false;
  try {
    const auto b = tf_buffer_.lookupTransform(odom_frame_, robot_base_frame_, ros::Time(0));
    // A static odom <- base_link comes back stamped 0: a robot that cannot turn.
    const bool moving = b.header.stamp.toSec() > 0.1;
    const auto a = moving ? tf_buffer_.lookupTransform(odom_frame_, robot_base_frame_,
                                                       b.header.stamp - ros::Duration(0.1))
                          : b;
    const double dt = (b.header.stamp - a.header.stamp).toSec();
    if (!moving) {
      have_rate = true;
    } else if (dt > 0.0) {
      yaw_rate =
          shortestAngularDistance(yawOf(a.transform.rotation), yawOf(b.transform.rotation)) / dt;
      have_rate = true;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    const double x = b.transform.translation.x, y = b.transform.translation.y;
    if (have_last_base_) travelled_m_ += std::hypot(x - last_base_x_, y - last_base_y_);
    last_base_x_ = x, last_base_y_ = y, have_last_base_ = true;
  } catch (const tf2::TransformException&) {
    // No odometry yet (or a robot without motion): yaw rate stays 0.
  }
  bool have_correction = false;
  geometry_msgs::TransformStamped map_odom;
  try {
    map_odom = tf_buffer_.lookupTransform(planning_frame_, odom_frame_, ros::Time(0));
    have_correction = true;
  } catch (const tf2::TransformException&) {
  }
  std::vector<SeamInput> inputs = relay_->inputs();
  const ros::Time now = ros::Time::now();
  SeamHealth health;
  health.header.stamp = now;
  health.header.frame_id = planning_frame_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    health.reference_range_m = limits_.reference_range_m;
    if (have_rate) yaw_rate_rps_ = yaw_rate;
    health.yaw_rate_rps = yaw_rate_rps_;
    if (have_correction) {
      health.map_odom_correction_m =
          std::hypot(map_odom.transform.translation.x, map_odom.transform.translation.y);
      health.map_odom_correction_yaw_rad = yawOf(map_odom.transform.rotation);
      // A static map <- odom (stamp 0) has no age.
      health.map_odom_pose_age_s =
          map_odom.header.stamp.isZero() ? -1.0 : (now - map_odom.header.stamp).toSec();
      correction_.add(now.toSec(), health.map_odom_correction_m, travelled_m_);
      if (health.map_odom_pose_age_s > limits_.max_map_odom_age_s) {
        health.warnings.push_back("map<-odom is " + toText(health.map_odom_pose_age_s) +
                                  " s old (localisation stopped?)");
      }
      for (const std::string& f : correction_.findings()) health.warnings.push_back(f);
    } else {
      health.map_odom_pose_age_s = -1.0;
      health.warnings.push_back("no transform '" + planning_frame_ + "' <- '" + odom_frame_ + "'");
    }
    health.map_odom_resets = static_cast<std::uint32_t>(correction_.resets());
    for (SeamInput& in : inputs) {
      in.expected_smear_m =
          expectedSmear(limits_.reference_range_m, yaw_rate_rps_, in.transform_age_p95_s);
      if (in.transform_age_p95_s > limits_.max_transform_age_s) {
        health.warnings.push_back(in.topic + ": transform age p95 " +
                                  toText(in.transform_age_p95_s) + " s > max_transform_age_s");
      }
      if (in.expected_smear_m > limits_.max_smear_m) {
        health.warnings.push_back(in.topic + ": expected smear " + toText(in.expected_smear_m) +
                                  " m at " + toText(limits_.reference_range_m) +
                                  " m > max_smear_m");
      }
      health.inputs.push_back(in);
    }
    health_ = health;
  }
  health_publisher_.publish(health);
  diagnostics_.force_update();
}

void HandoffRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const auto waits = relay_->waitingForTf();  // before mutex_: the relay has its own locks
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t waiting = 0;
  for (const auto& [topic, w] : waits) waiting += addTfWaits(status, topic + " ", w);
  status.add("planning_frame", planning_frame_);
  status.add("robot_base_frame", robot_base_frame_);
  status.add("yaw rate (rad/s)", health_.yaw_rate_rps);
  for (const SeamInput& in : health_.inputs) {
    status.add(in.topic + " messages", in.messages);
    status.add(in.topic + " tf failures", in.tf_failures);
    status.add(in.topic + " rejected (malformed)", in.rejected);
    status.add(in.topic + " transform age p50 (s)", in.transform_age_p50_s);
    status.add(in.topic + " transform age p95 (s)", in.transform_age_p95_s);
    status.add(in.topic + " expected smear at reference range (m)", in.expected_smear_m);
  }
  status.add("map<-odom correction (m)", health_.map_odom_correction_m);
  status.add("map<-odom correction yaw (rad)", health_.map_odom_correction_yaw_rad);
  status.add("map<-odom age (s, -1 static)", health_.map_odom_pose_age_s);
  status.add("map<-odom resets", health_.map_odom_resets);
  status.add("goals handed down", goals_);
  status.add("goals dropped (no transform at stamp)", goal_failures_);
  status.add("goals rejected (bad pose)", goals_rejected_);
  if (!last_goal_failure_.empty()) status.add("last goal failure", last_goal_failure_);
  if (config_errors_.report(status)) return;  // ERROR, with the first problem
  if (!health_.warnings.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, health_.warnings.front());
  } else if (waiting > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(waiting) + " message(s) waiting for tf (see 'waiting for tf')");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "seam healthy");
  }
}

}  // namespace downstream_perception
