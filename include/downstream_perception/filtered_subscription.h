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
    subscriber_ = std::make_unique<message_filters::Subscriber<M>>(nh, topic, 50);
    filter_ = std::make_unique<tf2_ros::MessageFilter<M>>(
        *subscriber_, tf, target_frame, static_cast<std::uint32_t>(queue_size), nh);
    filter_->registerCallback(on_message);
    filter_->registerFailureCallback(on_failure);
  }
  void unsubscribe() {
    if (subscriber_) subscriber_->unsubscribe();
    filter_.reset();
    subscriber_.reset();
  }
  /// Also wait for transforms up to `tolerance` after the stamp (a scan's last beam).
  void setTolerance(const ros::Duration& tolerance) {
    if (filter_) filter_->setTolerance(tolerance);
  }

 private:
  std::unique_ptr<message_filters::Subscriber<M>> subscriber_;
  std::unique_ptr<tf2_ros::MessageFilter<M>> filter_;
};

}  // namespace downstream_perception
