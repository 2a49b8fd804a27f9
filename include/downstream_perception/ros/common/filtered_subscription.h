// A topic subscription whose messages are released only once the transform into a target frame
// at their own stamp exists (tf2 MessageFilter), with a handler for the ones that never can be.
// Shared by the obstacle layer's sources, the tracked-obstacle layer and the handoff nodelet.
#pragma once

#include <message_filters/subscriber.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <boost/function.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/ros/common/tf_wait_monitor.h"

namespace downstream_perception {

/// A topic subscription released through a tf2 MessageFilter into a handler.
template <class M>
class FilteredSubscription {
 public:
  using Handler = boost::function<void(const boost::shared_ptr<const M>&)>;
  using FailureHandler = boost::function<void(
      const boost::shared_ptr<const M>&, tf2_ros::filter_failure_reasons::FilterFailureReason)>;

  void subscribe(ros::NodeHandle& nh, const std::string& topic, tf2_ros::Buffer& tf,
                 const std::string& target_frame, int queue_size, Handler on_message,
                 FailureHandler on_failure) {
    if (subscriber_) return;
    attach(nh, tf, target_frame, queue_size, std::move(on_message), std::move(on_failure));
    subscriber_ = std::make_unique<message_filters::Subscriber<M>>(nh, topic, 50);
    subscriber_->registerCallback([this](const boost::shared_ptr<const M>& m) { add(m); });
  }
  /// Without a subscription of its own: the owner checks each message first and add()s it.
  void attach(ros::NodeHandle& nh, tf2_ros::Buffer& tf, const std::string& target_frame,
              int queue_size, Handler on_message, FailureHandler on_failure) {
    tf_ = &tf;
    target_frame_ = target_frame;
    filter_ = std::make_unique<tf2_ros::MessageFilter<M>>(
        tf, target_frame, static_cast<std::uint32_t>(queue_size), nh);
    filter_->registerCallback([this, on_message](const boost::shared_ptr<const M>& m) {
      monitor_.left(m->header);
      on_message(m);
    });
    filter_->registerFailureCallback(
        [this, on_failure](const boost::shared_ptr<const M>& m,
                           tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
          monitor_.left(m->header);
          on_failure(m, reason);
        });
  }
  /// Hands a message to the filter (the monitor first: the filter may release it at once).
  void add(const boost::shared_ptr<const M>& m) {
    if (!filter_) return;
    monitor_.arrived(m->header);
    filter_->add(m);
  }
  /// Drops the messages waiting for their transform (the clock went back, say).
  void clearWaiting() {
    if (filter_) filter_->clear();
    monitor_.clear();
  }
  /// The messages held for their transform longer than `min_wait_s`, per frame, with tf2's
  /// reason (for diagnostics).
  std::vector<TfWait> waitingForTf(double min_wait_s = kTfWaitReportS) const {
    if (tf_ == nullptr) return {};
    return monitor_.waitingLongerThan(min_wait_s, *tf_, target_frame_);
  }
  void unsubscribe() {
    if (subscriber_) subscriber_->unsubscribe();
    filter_.reset();
    subscriber_.reset();
    monitor_.clear();
  }
  bool subscribed() const { return subscriber_ != nullptr; }
  /// The resolved topic name ("" before subscribe()).
  std::string topic() const { return subscriber_ ? subscriber_->getSubscriber().getTopic() : ""; }
  /// Publishers currently connected to the topic (0 before subscribe()).
  std::uint32_t numPublishers() const {
    return subscriber_ ? subscriber_->getSubscriber().getNumPublishers() : 0;
  }
  /// Also wait for transforms up to `tolerance` after the stamp (a scan's last beam).
  void setTolerance(const ros::Duration& tolerance) {
    if (filter_) filter_->setTolerance(tolerance);
  }

 private:
  std::unique_ptr<message_filters::Subscriber<M>> subscriber_;
  std::unique_ptr<tf2_ros::MessageFilter<M>> filter_;
  TfWaitMonitor monitor_;
  tf2_ros::Buffer* tf_ = nullptr;
  std::string target_frame_;
};

}  // namespace downstream_perception
