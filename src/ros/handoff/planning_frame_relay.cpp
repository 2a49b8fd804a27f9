#include "downstream_perception/ros/handoff/planning_frame_relay.h"

#include <tf2_sensor_msgs/tf2_sensor_msgs.h>

#include "downstream_perception/ros/common/conversions.h"
#include "downstream_perception/ros/common/message_checks.h"
#include "downstream_perception/ros/common/tf_failure.h"

namespace downstream_perception {

PlanningFrameRelay::PlanningFrameRelay(ros::NodeHandle nh, ros::NodeHandle pnh, tf2_ros::Buffer& tf,
                                       std::string planning_frame, const RelayTopics& topics)
    : nh_(nh),
      pnh_(pnh),
      tf_(tf),
      planning_frame_(std::move(planning_frame)),
      republish_(topics.republish),
      tf_queue_size_(topics.tf_queue_size) {
  if (republish_) {
    scans_publisher_ = pnh_.advertise<sensor_msgs::PointCloud2>("scans_planning", 10);
    clouds_publisher_ = pnh_.advertise<sensor_msgs::PointCloud2>("clouds_planning", 10);
    tracks_publisher_ = pnh_.advertise<TrackedObjectArray>("tracks_planning", 10);
  }
  for (const std::string& topic : topics.scans) {
    Input* input = &addInput(topic, "LaserScan");
    watch(input, &input->scans, &PlanningFrameRelay::onScan);
  }
  for (const std::string& topic : topics.clouds) {
    Input* input = &addInput(topic, "PointCloud2");
    watch(input, &input->clouds, &PlanningFrameRelay::onCloud);
  }
  for (const std::string& topic : topics.tracks) {
    Input* input = &addInput(topic, "TrackedObjectArray");
    watch(input, &input->tracks, &PlanningFrameRelay::onTracks);
  }
}

PlanningFrameRelay::Input& PlanningFrameRelay::addInput(const std::string& topic,
                                                        const std::string& type) {
  inputs_.push_back(std::make_unique<Input>());
  inputs_.back()->topic = ros::names::resolve(nh_.getNamespace(), topic);
  inputs_.back()->type = type;
  inputs_.back()->rejected.setLogPrefix("handoff: " + type + " on " + inputs_.back()->topic +
                                        " rejected");
  return *inputs_.back();
}

template <class M>
void PlanningFrameRelay::watch(
    Input* input, FilteredSubscription<M>* subscription,
    void (PlanningFrameRelay::*on_message)(Input*, const boost::shared_ptr<const M>&)) {
  subscription->subscribe(
      nh_, input->topic, tf_, planning_frame_, tf_queue_size_,
      [this, input, on_message](const boost::shared_ptr<const M>& m) {
        (this->*on_message)(input, m);
      },
      [this, input](const boost::shared_ptr<const M>& m,
                    tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onTfFailure(input, m->header.frame_id, m->header.stamp, tfFailureReason(reason));
      });
}

bool PlanningFrameRelay::arrive(Input* input, const ros::Time& stamp) {
  if (stamp.isZero()) {
    // tf reads stamp 0 as "latest": placing it would be exactly the smear this node reports.
    input->rejected.reject("malformed", "zero stamp: a measurement must carry its time");
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  input->ages.add((ros::Time::now() - stamp).toSec());
  return true;
}

void PlanningFrameRelay::onTfFailure(Input* input, const std::string& frame, const ros::Time& stamp,
                                     const std::string& why) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++input->tf_failures;
  }
  ROS_WARN_THROTTLE(2.0, "handoff: %s on %s ('%s' at %f) not placed in '%s': %s",
                    input->type.c_str(), input->topic.c_str(), frame.c_str(), stamp.toSec(),
                    planning_frame_.c_str(), why.c_str());
}

void PlanningFrameRelay::onScan(Input* input, const sensor_msgs::LaserScanConstPtr& msg) {
  if (!arrive(input, msg->header.stamp)) return;
  const std::string why = checkScan(*msg);
  if (!why.empty()) {
    input->rejected.reject("malformed", why);
    return;
  }
  // The stamp is the first beam's time; the last beam's transform is awaited too from now on.
  const ros::Duration sweep(std::max(0.0, msg->time_increment * (msg->ranges.size() - 1.0)));
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sweep > input->scan_sweep) {
      input->scan_sweep = sweep;
      input->scans.setTolerance(sweep);
    }
  }
  if (!republish_) return;
  sensor_msgs::PointCloud2 cloud;
  try {
    std::lock_guard<std::mutex> lock(projector_mutex_);
    // Each beam with the transform interpolated to its own time (a spinning robot's scan).
    projector_.transformLaserScanToPointCloud(planning_frame_, *msg, cloud, tf_);
  } catch (const tf2::TransformException& e) {
    onTfFailure(input, msg->header.frame_id, msg->header.stamp, e.what());
    return;
  }
  cloud.header.stamp = msg->header.stamp;
  scans_publisher_.publish(cloud);
}

void PlanningFrameRelay::onCloud(Input* input, const sensor_msgs::PointCloud2ConstPtr& msg) {
  if (!arrive(input, msg->header.stamp)) return;
  const std::string why = checkCloudLayout(*msg);
  if (!why.empty()) {
    input->rejected.reject("malformed", why);
    return;
  }
  if (!republish_) return;
  sensor_msgs::PointCloud2 out;
  try {
    // Released by the MessageFilter: the transform at the stamp exists.
    tf2::doTransform(*packedCloud(msg), out,
                     tf_.lookupTransform(planning_frame_, msg->header.frame_id, msg->header.stamp));
  } catch (const tf2::TransformException& e) {
    onTfFailure(input, msg->header.frame_id, msg->header.stamp, e.what());
    return;
  }
  out.header.stamp = msg->header.stamp;
  out.header.frame_id = planning_frame_;
  clouds_publisher_.publish(out);
}

void PlanningFrameRelay::onTracks(Input* input, const TrackedObjectArrayConstPtr& msg) {
  if (!arrive(input, msg->header.stamp) || !republish_) return;
  geometry_msgs::TransformStamped t;
  try {
    t = tf_.lookupTransform(planning_frame_, msg->header.frame_id, msg->header.stamp);
  } catch (const tf2::TransformException& e) {
    onTfFailure(input, msg->header.frame_id, msg->header.stamp, e.what());
    return;
  }
  TrackedObjectArray out;
  out.header = msg->header;
  out.header.frame_id = planning_frame_;  // the stamp stays the measurement's
  out.tracks.reserve(msg->tracks.size());
  for (const TrackedObject& o : msg->tracks) out.tracks.push_back(transformTrack(o, t));
  tracks_publisher_.publish(out);
}

std::vector<std::pair<std::string, std::vector<TfWait>>> PlanningFrameRelay::waitingForTf() const {
  std::vector<std::pair<std::string, std::vector<TfWait>>> out;
  for (const auto& input : inputs_) {  // the subscriptions are fixed after construction
    std::vector<TfWait> waits;
    const auto append = [&waits](std::vector<TfWait> w) {
      waits.insert(waits.end(), w.begin(), w.end());
    };
    append(input->scans.waitingForTf());  // an input has one of the three
    append(input->clouds.waitingForTf());
    append(input->tracks.waitingForTf());
    out.emplace_back(input->topic, std::move(waits));
  }
  return out;
}

std::vector<SeamInput> PlanningFrameRelay::inputs() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SeamInput> out;
  for (const auto& input : inputs_) {
    SeamInput in;
    in.topic = input->topic;
    in.type = input->type;
    in.messages = input->ages.total();
    in.tf_failures = input->tf_failures;
    in.rejected = input->rejected.total();
    in.transform_age_p50_s = input->ages.percentile(0.5);
    in.transform_age_p95_s = input->ages.percentile(0.95);
    in.transform_age_max_s = input->ages.percentile(1.0);
    out.push_back(in);
  }
  return out;
}

}  // namespace downstream_perception
