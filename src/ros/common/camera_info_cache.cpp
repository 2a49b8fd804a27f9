// CameraInfoCache: see the header for why images wait for their CameraInfo.
#include "downstream_perception/ros/common/camera_info_cache.h"

namespace downstream_perception {

sensor_msgs::ImageConstPtr WaitingImages::hold(const sensor_msgs::ImageConstPtr& image) {
  if (max_waiting_ == 0) return image;
  waiting_.push_back(image);
  if (waiting_.size() <= max_waiting_) return nullptr;
  sensor_msgs::ImageConstPtr oldest = waiting_.front();
  waiting_.pop_front();
  return oldest;
}

std::vector<sensor_msgs::ImageConstPtr> WaitingImages::release(const std::string* frame_id) {
  std::vector<sensor_msgs::ImageConstPtr> released;
  std::deque<sensor_msgs::ImageConstPtr> still;
  for (auto& image : waiting_) {
    if (frame_id == nullptr || image->header.frame_id == *frame_id) {
      released.push_back(std::move(image));
    } else {
      still.push_back(std::move(image));
    }
  }
  waiting_.swap(still);
  return released;
}

std::vector<sensor_msgs::ImageConstPtr> CameraInfoCache::update(
    const sensor_msgs::CameraInfo& info) {
  latest_[info.header.frame_id] = info;
  return waiting_.release(&info.header.frame_id);
}

const sensor_msgs::CameraInfo* CameraInfoCache::find(const std::string& frame_id) const {
  const auto it = latest_.find(frame_id);
  return it == latest_.end() ? nullptr : &it->second;
}

}  // namespace downstream_perception
