#include "downstream_perception/ros/tracking/tracker_ros.h"

#include <Eigen/Core>

#include <chrono>
#include <cmath>
#include <sstream>

#include "downstream_perception/TrackedObjectArray.h"
#include "downstream_perception/ros/common/config_errors.h"
#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/param_reader.h"
#include "downstream_perception/ros/common/tf_failure.h"
#include "downstream_perception/ros/common/timing_diagnostics.h"

namespace downstream_perception {

TrackerRos::TrackerRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), diagnostics_(nh, pnh, pnh.getNamespace()) {
  tracking_frame_ = "odom";
  readParam(pnh_, "tracking_frame", &tracking_frame_, &config_errors_);
  std::string mode = "metric";
  readParam(pnh_, "mode", &mode, &config_errors_);
  if (mode != "metric" && mode != "image") {
    config_errors_.add("parameter ~mode = '" + mode + "' is invalid; using 'metric'");
    mode = "metric";
  }
  image_mode_ = mode == "image";
  int tf_queue_size = 20;
  readParam(pnh_, "tf_queue_size", &tf_queue_size, &config_errors_);
  if (tf_queue_size < 1 || tf_queue_size > 10000) {
    config_errors_.add("parameter ~tf_queue_size must be in [1, 10000]; using 20");
    tf_queue_size = 20;
  }
  TrackerConfig config;
  config.mode = image_mode_ ? TrackerConfig::Mode::kImage : TrackerConfig::Mode::kMetric;
  tracker_ = std::make_unique<Tracker>(config);

  tracks_publisher_ = pnh_.advertise<TrackedObjectArray>("tracks", 10);
  markers_publisher_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  diagnostics_.setHardwareID("tracker " + tracking_frame_);
  diagnostics_.add("tracker", this, &TrackerRos::diagnose);

  // The server reads the YAML values (or the .cfg defaults, equal to TrackerConfig's metric
  // ones, where the mode has no default of its own) and calls reconfigure() at once: one code
  // path for start-up and live changes.
  applyModeDefaults(config.mode);
  reconfigure_.start(pnh_, this, &TrackerRos::reconfigure);

  if (image_mode_) {
    // Image boxes stay in their camera frame: no transform.
    subscriber_ =
        std::make_unique<message_filters::Subscriber<DetectedObjectArray>>(nh_, "detections", 20);
    subscriber_->registerCallback(
        boost::bind(&TrackerRos::onDetections, this, boost::placeholders::_1));
  } else {
    tf_buffer_ = std::make_shared<tf2_ros::Buffer>(ros::Duration(30.0));
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
    filtered_.subscribe(nh_, "detections", *tf_buffer_, tracking_frame_, tf_queue_size,
                        boost::bind(&TrackerRos::onDetections, this, boost::placeholders::_1),
                        boost::bind(&TrackerRos::onTfFailure, this, boost::placeholders::_1,
                                    boost::placeholders::_2));
  }
  // On the steady clock: a jump of the ROS clock must not hold up its own detection.
  clock_watch_ =
      nh_.createSteadyTimer(ros::WallDuration(kClockWatchPeriodS), &TrackerRos::watchClock, this);
  ROS_INFO("tracker: %s mode, tracking in '%s', detections on %s", mode.c_str(),
           image_mode_ ? "the detections' frame" : tracking_frame_.c_str(),
           ros::names::resolve(nh_.getNamespace(), "detections").c_str());
}

// Issue 21: image mode used to run on the metric defaults read in its own units. A key set in
// the YAML keeps its value and meaning; only unset keys take the mode's default, written to the
// parameter server (so `rosparam get` shows what runs) and logged once, here.
void TrackerRos::applyModeDefaults(TrackerConfig::Mode mode) {
  std::ostringstream applied;
  for (const auto& [name, value] : TrackerConfig::modeSpecificDefaults(mode)) {
    if (pnh_.hasParam(name)) continue;
    if (name == "min_hits") {  // the one integer parameter: the server reads it as an int
      pnh_.setParam(name, static_cast<int>(value));
    } else if (name == "confirm_at_start" || name == "maximize_matches") {  // read as bools
      pnh_.setParam(name, value != 0.0);
    } else {
      pnh_.setParam(name, value);
    }
    applied << (applied.tellp() > 0 ? ", " : "") << name << " " << value;
  }
  if (applied.tellp() > 0) {
    ROS_WARN(
        "tracker: %s mode defaults for the parameters not set: %s (before issue 21 image "
        "mode used the metric defaults; set a key to keep the old value)",
        mode == TrackerConfig::Mode::kImage ? "image" : "metric", applied.str().c_str());
  }
}

void TrackerRos::watchClock(const ros::SteadyTimerEvent&) {
  if (clock_jump_.check(ros::Time::now(), "tracker") == 0.0) {
    // Diagnostics also while nothing reaches the tracker (all detections waiting for tf, say);
    // the updater keeps its own period.
    diagnostics_.update();
    return;
  }
  filtered_.clearWaiting();  // messages waiting for old-timeline transforms
  if (tf_buffer_) restartTf(*tf_buffer_, tf_listener_, nh_);
  {
    // Tracks carry ages and stamps of the old timeline; the new one's frames are older than
    // them. Ids keep counting, so no id of the old timeline comes back for another object.
    std::lock_guard<std::mutex> lock(mutex_);
    tracker_->reset();
  }
  diagnostics_.force_update();  // outside mutex_ (diagnose() takes it): the updater, too,
                                // waits for its next (old-timeline) time
}

TrackerRos::~TrackerRos() {
  clock_watch_.stop();
  reconfigure_.stop();
  filtered_.unsubscribe();
  subscriber_.reset();
}

void TrackerRos::reconfigure(TrackerNodeConfig& c, std::uint32_t) {
  std::lock_guard<std::mutex> lock(mutex_);
  TrackerConfig next = tracker_->config();
  next.gate_confidence = c.gate_confidence;
  next.duplicate_confidence = c.duplicate_confidence;
  next.reid_confidence = c.reid_confidence;
  next.min_iou = c.min_iou;
  next.accel_psd = c.accel_psd;
  next.measurement_std = c.measurement_std;
  next.initial_velocity_std = c.initial_velocity_std;
  next.min_hits = c.min_hits;
  next.confirm_at_start = c.confirm_at_start;
  next.maximize_matches = c.maximize_matches;
  next.start_confirm_score = c.start_confirm_score;
  next.max_age_s = c.max_age_s;
  next.high_score = c.high_score;
  next.low_score = c.low_score;
  next.second_pass = c.second_pass;
  next.class_aware = c.class_aware;
  try {
    tracker_->setConfig(next);
  } catch (const std::invalid_argument& e) {
    config_errors_.add(std::string(e.what()) + "; keeping the previous settings");
  }
}

void TrackerRos::onTfFailure(const DetectedObjectArrayConstPtr& msg,
                             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  std::ostringstream detail;
  detail << "frame '" << msg->header.frame_id << "' -> '" << tracking_frame_ << "' at stamp "
         << msg->header.stamp;
  rejected_.reject(tfFailureReason(reason), detail.str());
}

bool TrackerRos::toCore(const DetectedObjectArray& msg, std::vector<Detection>* out,
                        std::string* why) {
  Eigen::Isometry3d to_tracking = Eigen::Isometry3d::Identity();
  if (!image_mode_) {
    try {
      to_tracking = toEigen(
          tf_buffer_->lookupTransform(tracking_frame_, msg.header.frame_id, msg.header.stamp)
              .transform);
    } catch (const tf2::TransformException& e) {
      *why = std::string("tf: lookup at stamp failed: ") + e.what();
      return false;
    }
  }
  // The top-left 2 x 2 of the rotation turns the planar covariances: C' = R C R^T.
  const Eigen::Matrix2d rot = to_tracking.linear().topLeftCorner<2, 2>();
  for (const auto& d : msg.detections) {
    if (d.kind != DetectedObject::BOX && d.kind != DetectedObject::POSITION) {
      ++detections_unknown_kind_;  // neither a box nor a position: nothing to read
      ROS_WARN_THROTTLE(2.0, "tracker: detection of unknown kind %d dropped (BOX=0, POSITION=1)",
                        static_cast<int>(d.kind));
      continue;
    }
    Detection c;
    c.class_id = d.class_id;
    c.score = d.score;
    c.truth_id = d.truth_id;
    if (!d.label.empty()) labels_[d.class_id] = d.label;
    if (image_mode_ || d.kind == DetectedObject::BOX) {
      if (!image_mode_) {
        // A box in metric mode cannot be placed: count it as invalid rather than guess.
        c.x = std::nan("");
      }
      c.box = {d.x_min, d.y_min, d.x_max, d.y_max};
    } else {
      const Eigen::Vector3d p =
          to_tracking * Eigen::Vector3d(d.position.x, d.position.y, d.position.z);
      c.x = p.x();
      c.y = p.y();
      boost::array<double, 4> cov = d.position_covariance;
      rotateCovariance(rot, &cov);
      c.cov_xx = cov[0];
      c.cov_xy = 0.5 * (cov[1] + cov[2]);
      c.cov_yy = cov[3];
      c.size_x = d.size_x;
      c.size_y = d.size_y;
    }
    out->push_back(c);
  }
  return true;
}

void TrackerRos::onDetections(const DetectedObjectArrayConstPtr& msg) {
  if (msg->header.stamp.isZero()) {
    rejected_.reject("bad message: zero stamp", "detections must carry their measurement time");
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<Detection> detections;
    std::string why;
    if (!toCore(*msg, &detections, &why)) {
      rejected_.count("tf: lookup at stamp failed");
      ROS_WARN_THROTTLE(2.0, "tracker: %s", why.c_str());
      return;
    }
    const auto t0 = std::chrono::steady_clock::now();
    try {
      last_ = tracker_->step(msg->header.stamp.toSec(), detections);
    } catch (const std::invalid_argument& e) {
      rejected_.count("bad message: stamp not newer than the previous frame");
      ROS_WARN_THROTTLE(2.0, "tracker: %s", e.what());
      return;
    }
    step_us_.add(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    total_.accumulate(last_);
    ++frames_;
    std_msgs::Header header = msg->header;
    if (!image_mode_) header.frame_id = tracking_frame_;
    publish(header);
  }
  diagnostics_.update();  // outside the lock: diagnose() takes it
}

void TrackerRos::publish(const std_msgs::Header& header) {
  TrackedObjectArrayPtr out(new TrackedObjectArray);
  out->header = header;
  for (const auto& t : tracker_->tracks()) {
    TrackedObject m;
    m.id = t.id;
    m.class_id = t.class_id;
    const auto label = labels_.find(t.class_id);
    if (label != labels_.end()) m.label = label->second;
    m.state = static_cast<std::uint8_t>(t.state);
    m.position.x = t.position.x();
    m.position.y = t.position.y();
    m.velocity.x = t.velocity.x();
    m.velocity.y = t.velocity.y();
    for (int k = 0; k < 4; ++k) {
      m.position_covariance[k] = t.position_cov(k / 2, k % 2);
      m.velocity_covariance[k] = t.velocity_cov(k / 2, k % 2);
    }
    m.size_x = static_cast<float>(t.size_x);
    m.size_y = static_cast<float>(t.size_y);
    m.score = static_cast<float>(t.score);
    m.age = t.age_s;
    m.hits = static_cast<std::uint32_t>(t.hits);
    m.time_since_update = t.time_since_update_s;
    m.truth_id = t.truth_id;
    out->tracks.push_back(m);
  }
  markers_publisher_.publish(markers_.build(*out));
  tracks_publisher_.publish(out);
}

void TrackerRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::size_t rejected = rejected_.report(status);
  status.add("frames", frames_);
  status.add("clock jumps back (tracks reset)", clock_jump_.jumps());
  status.add("tracks alive", last_.tracks);
  status.add("tracks confirmed", last_.confirmed);
  status.add("detections (total)", total_.detections);
  status.add("detections invalid (total)", total_.detections_rejected_invalid);
  status.add("detections out of range (total)", total_.detections_rejected_out_of_range);
  status.add("detections of unknown kind (total)", detections_unknown_kind_);
  status.add("detections below low_score (total)", total_.detections_ignored_low_score);
  status.add("detections outside every gate: births (total)", total_.births);
  status.add("matched first pass (total)", total_.matched_first_pass);
  status.add("matched second pass (total)", total_.matched_second_pass);
  status.add("duplicates removed (total)", total_.duplicates_removed);
  status.add("re-identified after a gap (total)", total_.reidentified);
  status.add("deaths (total)", total_.deaths);
  status.add("ID switches vs truth ids (total)", total_.id_switches);
  status.add("step time mean (us)", step_us_.mean());
  status.add("step time max (us)", step_us_.max);
  addTimingHistogram(status, "step time", "us", step_us_.histogram);
  const std::vector<std::string> config_errors = config_errors_.all();
  addConfigErrors(status, config_errors);
  const std::size_t waiting = addTfWaits(status, "", filtered_.waitingForTf());
  if (!config_errors.empty()) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, config_errors.front());
  } else if (waiting > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(waiting) + " message(s) waiting for tf (see 'waiting for tf')");
  } else if (frames_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no detections received yet");
  } else if (rejected > 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   std::to_string(rejected) + " message(s) rejected (see counts)");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
}

}  // namespace downstream_perception
