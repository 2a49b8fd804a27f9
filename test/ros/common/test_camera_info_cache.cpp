// CameraInfoCache: images that overtake their frame's first CameraInfo wait for it (bounded),
// and come out in order, only for their own frame.
#include <gtest/gtest.h>

#include <string>

#include "downstream_perception/ros/common/camera_info_cache.h"

namespace downstream_perception {
namespace {

sensor_msgs::ImageConstPtr image(const std::string& frame, std::uint32_t seq) {
  sensor_msgs::ImagePtr m(new sensor_msgs::Image);
  m->header.frame_id = frame;
  m->header.seq = seq;
  return m;
}

sensor_msgs::CameraInfo info(const std::string& frame, std::uint32_t width) {
  sensor_msgs::CameraInfo m;
  m.header.frame_id = frame;
  m.width = width;
  return m;
}

TEST(CameraInfoCache, AnImageBeforeItsFramesFirstCameraInfoComesOutWithIt) {
  CameraInfoCache cache(10);
  EXPECT_EQ(cache.find("depth"), nullptr);
  EXPECT_EQ(cache.wait(image("depth", 1)), nullptr);
  EXPECT_EQ(cache.wait(image("other", 2)), nullptr);
  EXPECT_EQ(cache.wait(image("depth", 3)), nullptr);
  EXPECT_EQ(cache.waiting(), 3u);
  const auto released = cache.update(info("depth", 640));
  ASSERT_EQ(released.size(), 2u);
  EXPECT_EQ(released[0]->header.seq, 1u);  // oldest first
  EXPECT_EQ(released[1]->header.seq, 3u);
  EXPECT_EQ(cache.waiting(), 1u);  // "other" still waits for its own
  ASSERT_NE(cache.find("depth"), nullptr);
  EXPECT_EQ(cache.find("depth")->width, 640u);
  EXPECT_EQ(cache.find("other"), nullptr);
}

TEST(CameraInfoCache, KeepsTheLatestCameraInfoPerFrame) {
  CameraInfoCache cache(4);
  EXPECT_TRUE(cache.update(info("a", 320)).empty());
  EXPECT_TRUE(cache.update(info("b", 160)).empty());
  EXPECT_TRUE(cache.update(info("a", 640)).empty());
  EXPECT_EQ(cache.find("a")->width, 640u);
  EXPECT_EQ(cache.find("b")->width, 160u);
}

TEST(CameraInfoCache, AFullQueuePushesOutItsOldestImage) {
  CameraInfoCache cache(2);
  EXPECT_EQ(cache.wait(image("x", 1)), nullptr);
  EXPECT_EQ(cache.wait(image("x", 2)), nullptr);
  const auto out = cache.wait(image("x", 3));
  ASSERT_NE(out, nullptr);
  EXPECT_EQ(out->header.seq, 1u);
  EXPECT_EQ(cache.waiting(), 2u);  // memory stays bounded by max_waiting
  const auto released = cache.update(info("x", 1));
  ASSERT_EQ(released.size(), 2u);
  EXPECT_EQ(released[0]->header.seq, 2u);
  EXPECT_EQ(cache.waiting(), 0u);
}

TEST(CameraInfoCache, WithNoRoomAnImageIsReturnedAtOnce) {
  CameraInfoCache cache(0);
  const auto in = image("x", 7);
  EXPECT_EQ(cache.wait(in), in);
  EXPECT_EQ(cache.waiting(), 0u);
}

TEST(CameraInfoCache, AClockJumpDropsTheWaitingImagesButKeepsTheCameraInfos) {
  CameraInfoCache cache(4);
  cache.update(info("a", 320));
  EXPECT_EQ(cache.wait(image("b", 1)), nullptr);
  cache.clearWaiting();
  EXPECT_EQ(cache.waiting(), 0u);
  EXPECT_TRUE(cache.update(info("b", 160)).empty());  // nothing of the old timeline comes out
  EXPECT_EQ(cache.find("a")->width, 320u);
}

}  // namespace
}  // namespace downstream_perception
