// The latest CameraInfo per frame id, and the images that came before their frame's first one.
// A camera driver publishes image and CameraInfo on two topics; ROS delivers each topic on its
// own connection, so nothing orders them against each other and at start-up (or in a bag
// replay) the first image can overtake the first CameraInfo. A consumer that dropped such an
// image lost a frame by chance: here it waits (a bounded number of them) for its CameraInfo.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstddef>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace downstream_perception {

/// Images held until what they need arrives (their CameraInfo), oldest first, at most
/// `max_waiting` of them. Not thread-safe: the owner's lock guards it.
class WaitingImages {
 public:
  explicit WaitingImages(std::size_t max_waiting = 0) : max_waiting_(max_waiting) {}

  /// Holds `image`. Returns the image it pushes out when max_waiting images already wait (the
  /// oldest; `image` itself when max_waiting is 0), else null.
  sensor_msgs::ImageConstPtr hold(const sensor_msgs::ImageConstPtr& image);
  /// Removes and returns the held images of frame `frame_id` (all of them for null), oldest
  /// first.
  std::vector<sensor_msgs::ImageConstPtr> release(const std::string* frame_id = nullptr);
  void clear() { waiting_.clear(); }
  std::size_t size() const { return waiting_.size(); }
  std::size_t maxWaiting() const { return max_waiting_; }

 private:
  std::size_t max_waiting_;
  std::deque<sensor_msgs::ImageConstPtr> waiting_;  ///< oldest first
};

/// Not thread-safe: the owner's lock guards it.
class CameraInfoCache {
 public:
  /// At most `max_waiting` images wait (0: none wait; an image without CameraInfo is dropped).
  explicit CameraInfoCache(std::size_t max_waiting) : waiting_(max_waiting) {}

  /// Stores `info` as its frame's latest; returns the images that waited for that frame,
  /// oldest first (the caller checks them against `info` like any other image).
  std::vector<sensor_msgs::ImageConstPtr> update(const sensor_msgs::CameraInfo& info);

  /// The latest CameraInfo of `frame_id`, or null before its first.
  const sensor_msgs::CameraInfo* find(const std::string& frame_id) const;

  /// Holds an image whose frame has no CameraInfo yet (WaitingImages::hold).
  sensor_msgs::ImageConstPtr wait(const sensor_msgs::ImageConstPtr& image) {
    return waiting_.hold(image);
  }

  /// Drops the waiting images (a clock jump: they belong to the old timeline).
  void clearWaiting() { waiting_.clear(); }
  std::size_t waiting() const { return waiting_.size(); }
  std::size_t maxWaiting() const { return waiting_.maxWaiting(); }

 private:
  std::map<std::string, sensor_msgs::CameraInfo> latest_;
  WaitingImages waiting_;
};

}  // namespace downstream_perception
