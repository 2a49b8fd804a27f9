#include "downstream_perception/handoff_ros.h"

#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>  // PoseStamped in tf2_ros::Buffer::transform

#include <cmath>
#include <sstream>

#include "downstream_perception/config_errors.h"
#include "downstream_perception/core/se2.h"
#include "downstream_perception/tf_failure.h"
#include "downstream_perception/track_transform.h"

namespace downstream_perception {

HandoffRos::HandoffRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_, nh), diagnostics_(nh, pnh) {
  loadParameters();
  correction_ = CorrectionMonitor(correction_config_);
  health_.map_odom_pose_age_s = -1.0;  // no report yet
  std::vector<std::string> scan_topics, track_topics;
  pnh_.param("scan_topics", scan_topics, std::vector<std::string>{});
  pnh_.param("track_topics", track_topics, std::vector<std::string>{});
  for (const std::string& topic : scan_topics) {
    Input* input = &addInput(topic, "LaserScan");
    input->scans.subscribe(
        nh_, topic, tf_buffer_, planning_frame_, 20,
        [this, input](const sensor_msgs::LaserScanConstPtr& m) {
          recordArrival(input, m->header.stamp);
        },
        [this, input](const sensor_msgs::LaserScanConstPtr& m,
                      tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          onTfFailure(input, m->header.frame_id, m->header.stamp, reason);
        });
  }
  for (const std::string& topic : track_topics) {
    Input* input = &addInput(topic, "TrackedObjectArray");
    input->tracks.subscribe(
        nh_, topic, tf_buffer_, planning_frame_, 20,
        [this, input](const TrackedObjectArrayConstPtr& m) { onTracks(input, m); },
        [this, input](const TrackedObjectArrayConstPtr& m,
                      tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          onTfFailure(input, m->header.frame_id, m->header.stamp, reason);
        });
  }
  goal_publisher_ = pnh_.advertise<geometry_msgs::PoseStamped>("goal_base", 10);
  tracks_publisher_ = pnh_.advertise<TrackedObjectArray>("tracks_planning", 10);
  health_publisher_ = pnh_.advertise<SeamHealth>("seam_health", 1);
  goal_subscriber_ = nh_.subscribe("goal", 10, &HandoffRos::onGoal, this);
  transform_service_ = pnh_.advertiseService("transform_pose", &HandoffRos::onTransformPose, this);
  diagnostics_.setHardwareID("handoff");
  diagnostics_.add("seam", this, &HandoffRos::diagnose);
  timer_ = nh_.createTimer(ros::Duration(1.0 / health_rate_hz_), &HandoffRos::onTimer, this);
  ROS_INFO("handoff: planning in '%s', goals to '%s', %zu scan and %zu track inputs",
           planning_frame_.c_str(), robot_base_frame_.c_str(), scan_topics.size(),
           track_topics.size());
}

void HandoffRos::loadParameters() {
  pnh_.param("planning_frame", planning_frame_, planning_frame_);
  pnh_.param("odom_frame", odom_frame_, odom_frame_);
  pnh_.param("robot_base_frame", robot_base_frame_, robot_base_frame_);
  pnh_.param("reference_range_m", reference_range_m_, reference_range_m_);
  pnh_.param("max_transform_age_s", max_transform_age_s_, max_transform_age_s_);
  pnh_.param("max_smear_m", max_smear_m_, max_smear_m_);
  pnh_.param("max_map_odom_age_s", max_map_odom_age_s_, max_map_odom_age_s_);
  pnh_.param("health_rate_hz", health_rate_hz_, health_rate_hz_);
  pnh_.param("correction_window_s", correction_config_.window_s, correction_config_.window_s);
  pnh_.param("correction_reset_drop_m", correction_config_.reset_drop_m,
             correction_config_.reset_drop_m);
  pnh_.param("max_correction_m", correction_config_.max_correction_m,
             correction_config_.max_correction_m);
  pnh_.param("correction_min_travel_m", correction_config_.min_travel_m,
             correction_config_.min_travel_m);
  const auto positive = [this](const char* name, double* value, double fallback) {
    if (std::isfinite(*value) && *value > 0.0) return;
    config_errors_.push_back(std::string("parameter ") + name + " = " + toText(*value) +
                             " must be > 0; using " + toText(fallback));
    ROS_ERROR("handoff: %s", config_errors_.back().c_str());
    *value = fallback;
  };
  positive("reference_range_m", &reference_range_m_, 5.0);
  positive("max_transform_age_s", &max_transform_age_s_, 0.1);
  positive("max_smear_m", &max_smear_m_, 0.05);
  positive("max_map_odom_age_s", &max_map_odom_age_s_, 2.0);
  positive("health_rate_hz", &health_rate_hz_, 2.0);
  const std::string why = correction_config_.validate();
  if (!why.empty()) {
    config_errors_.push_back(why + "; using the defaults");
    ROS_ERROR("handoff: %s", config_errors_.back().c_str());
    correction_config_ = CorrectionMonitorConfig();
  }
}

HandoffRos::Input& HandoffRos::addInput(const std::string& topic, const std::string& type) {
  inputs_.push_back(std::make_unique<Input>());
  inputs_.back()->topic = ros::names::resolve(topic);
  inputs_.back()->type = type;
  return *inputs_.back();
}

void HandoffRos::recordArrival(Input* input, const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  input->ages.add((ros::Time::now() - stamp).toSec());
}

void HandoffRos::onTfFailure(Input* input, const std::string& frame, const ros::Time& stamp,
                             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++input->tf_failures;
  }
  ROS_WARN_THROTTLE(2.0, "handoff: %s on %s ('%s' at %f) not placed in '%s': %s",
                    input->type.c_str(), input->topic.c_str(), frame.c_str(), stamp.toSec(),
                    planning_frame_.c_str(), tfFailureReason(reason));
}

void HandoffRos::onTracks(Input* input, const TrackedObjectArrayConstPtr& msg) {
  recordArrival(input, msg->header.stamp);
  geometry_msgs::TransformStamped t;
  try {
    // Released by the MessageFilter: the transform at the stamp exists.
    t = tf_buffer_.lookupTransform(planning_frame_, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException&) {
    onTfFailure(input, msg->header.frame_id, msg->header.stamp,
                tf2_ros::filter_failure_reasons::Unknown);
    return;
  }
  TrackedObjectArray out;
  out.header = msg->header;
  out.header.frame_id = planning_frame_;  // the stamp stays the measurement's
  out.tracks.reserve(msg->tracks.size());
  for (const TrackedObject& o : msg->tracks) out.tracks.push_back(transformTrack(o, t));
  tracks_publisher_.publish(out);
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
  geometry_msgs::PoseStamped out;
  std::string why;
  if (!transformPose(*msg, robot_base_frame_, &out, &why)) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++goal_failures_;
    last_goal_failure_ = why;
    ROS_WARN_THROTTLE(2.0, "handoff: goal dropped: %s", why.c_str());
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++goals_;
  }
  goal_publisher_.publish(out);
}

bool HandoffRos::onTransformPose(TransformPose::Request& req, TransformPose::Response& res) {
  std::string why;
  res.success = transformPose(req.pose, req.target_frame, &res.pose, &why);
  res.message = res.success ? "ok" : why;
  return true;
}

void HandoffRos::onTimer(const ros::TimerEvent&) {
  // Yaw rate and travel from odom <- base_link: the latest transform and one 0.1 s older.
  double yaw_rate = 0.0;
  bool have_rate = false;
  try {
    const auto b = tf_buffer_.lookupTransform(odom_frame_, robot_base_frame_, ros::Time(0));
    const auto a = tf_buffer_.lookupTransform(odom_frame_, robot_base_frame_,
                                              b.header.stamp - ros::Duration(0.1));
    const double dt = (b.header.stamp - a.header.stamp).toSec();
    if (dt > 0.0) {
      yaw_rate = shortestAngularDistance(tf2::getYaw(a.transform.rotation),
                                         tf2::getYaw(b.transform.rotation)) /
                 dt;
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
  const ros::Time now = ros::Time::now();
  SeamHealth health;
  health.header.stamp = now;
  health.header.frame_id = planning_frame_;
  health.reference_range_m = reference_range_m_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (have_rate) yaw_rate_rps_ = yaw_rate;
    health.yaw_rate_rps = yaw_rate_rps_;
    if (have_correction) {
      health.map_odom_correction_m =
          std::hypot(map_odom.transform.translation.x, map_odom.transform.translation.y);
      health.map_odom_correction_yaw_rad = tf2::getYaw(map_odom.transform.rotation);
      // A static map <- odom (stamp 0) has no age.
      health.map_odom_pose_age_s =
          map_odom.header.stamp.isZero() ? -1.0 : (now - map_odom.header.stamp).toSec();
      correction_.add(now.toSec(), health.map_odom_correction_m, travelled_m_);
      if (health.map_odom_pose_age_s > max_map_odom_age_s_) {
        health.warnings.push_back("map<-odom is " + toText(health.map_odom_pose_age_s) +
                                  " s old (localisation stopped?)");
      }
      for (const std::string& f : correction_.findings()) health.warnings.push_back(f);
    } else {
      health.map_odom_pose_age_s = -1.0;
      health.warnings.push_back("no transform '" + planning_frame_ + "' <- '" + odom_frame_ + "'");
    }
    health.map_odom_resets = static_cast<std::uint32_t>(correction_.resets());
    for (const auto& input : inputs_) {
      SeamInput in;
      in.topic = input->topic;
      in.type = input->type;
      in.messages = input->ages.total();
      in.tf_failures = input->tf_failures;
      in.transform_age_p50_s = input->ages.percentile(0.5);
      in.transform_age_p95_s = input->ages.percentile(0.95);
      in.transform_age_max_s = input->ages.percentile(1.0);
      in.expected_smear_m =
          expectedSmear(reference_range_m_, yaw_rate_rps_, in.transform_age_p95_s);
      if (in.transform_age_p95_s > max_transform_age_s_) {
        health.warnings.push_back(in.topic + ": transform age p95 " +
                                  toText(in.transform_age_p95_s) + " s > max_transform_age_s");
      }
      if (in.expected_smear_m > max_smear_m_) {
        health.warnings.push_back(in.topic + ": expected smear " + toText(in.expected_smear_m) +
                                  " m at " + toText(reference_range_m_) + " m > max_smear_m");
      }
      health.inputs.push_back(in);
    }
    health_ = health;
  }
  health_publisher_.publish(health);
  diagnostics_.force_update();
}

void HandoffRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("planning_frame", planning_frame_);
  status.add("robot_base_frame", robot_base_frame_);
  status.add("yaw rate (rad/s)", health_.yaw_rate_rps);
  for (const SeamInput& in : health_.inputs) {
    status.add(in.topic + " messages", in.messages);
    status.add(in.topic + " tf failures", in.tf_failures);
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
  if (!last_goal_failure_.empty()) status.add("last goal failure", last_goal_failure_);
  addConfigErrors(status, config_errors_);
  if (!config_errors_.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors_.front());
  } else if (!health_.warnings.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, health_.warnings.front());
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "seam healthy");
  }
}

}  // namespace downstream_perception
