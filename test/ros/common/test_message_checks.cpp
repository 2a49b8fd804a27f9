// The shared message checks, without a ROS master: every malformed layout a hostile or buggy
// publisher can send is refused with a reason, and what passes can be read within its data.
#include <gtest/gtest.h>

#include <sensor_msgs/image_encodings.h>
#include <boost/make_shared.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "downstream_perception/ros/common/message_checks.h"

using namespace downstream_perception;  // NOLINT

namespace {

sensor_msgs::PointField field(const std::string& name, std::uint32_t offset,
                              std::uint8_t datatype = sensor_msgs::PointField::FLOAT32) {
  sensor_msgs::PointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = datatype;
  f.count = 1;
  return f;
}

/// width x height points of x, y, z, intensity (16 bytes), rows padded by `row_padding` bytes;
/// point k holds (k, 2k, 3k).
sensor_msgs::PointCloud2 xyziCloud(std::uint32_t width, std::uint32_t height,
                                   std::uint32_t row_padding = 0) {
  sensor_msgs::PointCloud2 c;
  c.header.frame_id = "lidar";
  c.width = width;
  c.height = height;
  c.fields = {field("x", 0), field("y", 4), field("z", 8), field("intensity", 12)};
  c.point_step = 16;
  c.row_step = width * 16 + row_padding;
  c.data.assign(static_cast<std::size_t>(c.row_step) * height, 0);
  std::uint32_t k = 0;
  for (std::uint32_t row = 0; row < height; ++row) {
    for (std::uint32_t col = 0; col < width; ++col, ++k) {
      const float xyz[3] = {float(k), 2.0f * k, 3.0f * k};
      std::memcpy(c.data.data() + row * c.row_step + col * 16, xyz, sizeof(xyz));
    }
  }
  return c;
}

}  // namespace

TEST(CheckCloudLayout, AcceptsAPaddedCloudAndVisitsEachPointOnce) {
  const sensor_msgs::PointCloud2 cloud = xyziCloud(5, 3, 7);
  std::size_t x_offset = 99;
  ASSERT_EQ(checkCloudLayout(cloud, &x_offset), "");
  EXPECT_EQ(x_offset, 0u);
  std::vector<float> xs;
  forEachCloudPoint(cloud, x_offset, [&](float x, float y, float z) {
    EXPECT_EQ(y, 2.0f * x);
    EXPECT_EQ(z, 3.0f * x);
    xs.push_back(x);
  });
  ASSERT_EQ(xs.size(), 15u);
  for (std::size_t k = 0; k < xs.size(); ++k) EXPECT_EQ(xs[k], float(k));
}

TEST(CheckCloudLayout, AcceptsAnEmptyCloud) {
  EXPECT_EQ(checkCloudLayout(xyziCloud(0, 0)), "");
  EXPECT_EQ(checkCloudLayout(xyziCloud(0, 1)), "");
}

TEST(CheckCloudLayout, RefusesPointStepZero) {  // once an endless loop in the TSDF nodelet
  sensor_msgs::PointCloud2 c = xyziCloud(4, 1);
  c.point_step = 0;
  EXPECT_NE(checkCloudLayout(c).find("point_step 0"), std::string::npos) << checkCloudLayout(c);
}

TEST(CheckCloudLayout, RefusesFieldOffsetsPastThePoint) {
  sensor_msgs::PointCloud2 c = xyziCloud(4, 1);
  c.fields[2].offset = 4000000000u;  // z far past the point (a SEGV once)
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(4, 1);
  c.fields[0].offset = 4000;  // all three past a 16-byte point (garbage read once)
  c.fields[1].offset = 4004;
  c.fields[2].offset = 4008;
  EXPECT_NE(checkCloudLayout(c).find("point_step"), std::string::npos);
}

TEST(CheckCloudLayout, RefusesOffsetsThatWrapAroundIn32Bits) {
  // x at 2^32 - 8: in 32-bit arithmetic y = x + 4 and z = x + 8 wrap to 2^32 - 4 and 0, and
  // x + 12 wraps to 4 <= point_step; only 64-bit sums see that x lies 4 GB past the point.
  sensor_msgs::PointCloud2 c = xyziCloud(4, 1);
  c.fields[0].offset = 0xFFFFFFF8u;
  c.fields[1].offset = 0xFFFFFFFCu;
  c.fields[2].offset = 0u;
  EXPECT_NE(checkCloudLayout(c), "");
  c.fields[1].offset = 0xFFFFFFFCu;
  c.fields[2].offset = 0xFFFFFFFCu + 4u;  // wraps to 0 as well
  EXPECT_NE(checkCloudLayout(c), "");
}

TEST(CheckCloudLayout, RefusesWidthTimesPointStepThatWrapsIn32Bits) {
  sensor_msgs::PointCloud2 c = xyziCloud(1, 1);
  c.width = 0x10000000u;  // * 16 = 2^32: 0 in 32 bits
  c.row_step = 16;
  c.data.assign(16, 0);
  EXPECT_NE(checkCloudLayout(c).find("width * point_step"), std::string::npos);
}

TEST(CheckCloudLayout, RefusesDataSizesThatDoNotMatch) {
  sensor_msgs::PointCloud2 c = xyziCloud(4, 2);
  c.data.pop_back();
  EXPECT_NE(checkCloudLayout(c).find("data holds"), std::string::npos);
  c = xyziCloud(4, 2);
  c.height = 0xFFFFFFFFu;  // row_step * height overflows 32 bits
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(4, 2);
  c.row_step = 8;  // < width * point_step
  EXPECT_NE(checkCloudLayout(c), "");
}

TEST(CheckCloudLayout, RefusesMissingWrongTypedOrScatteredFields) {
  sensor_msgs::PointCloud2 c = xyziCloud(2, 1);
  c.fields.erase(c.fields.begin() + 1);  // no y
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(2, 1);
  c.fields[2].datatype = sensor_msgs::PointField::FLOAT64;
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(2, 1);
  std::swap(c.fields[1].offset, c.fields[3].offset);  // y after intensity
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(2, 1);
  c.fields[0].count = 0;
  EXPECT_NE(checkCloudLayout(c), "");
  c = xyziCloud(2, 1);
  c.is_bigendian = true;
  EXPECT_NE(checkCloudLayout(c), "");
}

TEST(CheckCloudLayout, AcceptsXyzAfterOtherFields) {
  sensor_msgs::PointCloud2 c = xyziCloud(3, 1);
  c.fields = {field("intensity", 0), field("x", 4), field("y", 8), field("z", 12)};
  std::size_t x_offset = 0;
  ASSERT_EQ(checkCloudLayout(c, &x_offset), "");
  EXPECT_EQ(x_offset, 4u);
  c.point_step = 15;  // z would end at byte 16
  c.row_step = 45;
  c.data.resize(45);
  EXPECT_NE(checkCloudLayout(c), "");
}

namespace {

sensor_msgs::Image depthImage(std::uint32_t width, std::uint32_t height, const std::string& enc) {
  sensor_msgs::Image image;
  image.width = width;
  image.height = height;
  image.encoding = enc;
  const std::uint32_t pixel = enc == sensor_msgs::image_encodings::TYPE_32FC1 ? 4 : 2;
  image.step = width * pixel;
  image.data.assign(static_cast<std::size_t>(image.step) * height, 0);
  return image;
}

}  // namespace

TEST(CheckDepthImage, AcceptsMetresAndMillimetres) {
  std::string why;
  EXPECT_TRUE(checkDepthImage(depthImage(4, 3, "32FC1"), &why)) << why;
  sensor_msgs::Image mm = depthImage(2, 1, "16UC1");
  const std::uint16_t values[2] = {1500, 0};
  std::memcpy(mm.data.data(), values, sizeof(values));
  std::vector<float> metres;
  ASSERT_TRUE(depthImageToMetres(mm, &metres, &why)) << why;
  ASSERT_EQ(metres.size(), 2u);
  EXPECT_FLOAT_EQ(metres[0], 1.5f);
  EXPECT_TRUE(std::isnan(metres[1]));  // 0 mm = no measurement
  // A driver's 0 for "too far", asked for as a no-return: +Inf (REP 118), not NaN (invalid).
  ASSERT_TRUE(depthImageToMetres(mm, &metres, &why, true)) << why;
  EXPECT_FLOAT_EQ(metres[0], 1.5f);
  EXPECT_EQ(metres[1], std::numeric_limits<float>::infinity());
}

TEST(CheckDepthImage, RefusesInconsistentSizes) {
  std::string why;
  sensor_msgs::Image image = depthImage(4, 3, "32FC1");
  image.step = 8;  // < 4 pixels of 4 bytes
  EXPECT_FALSE(checkDepthImage(image, &why));
  image = depthImage(4, 3, "32FC1");
  image.data.pop_back();
  EXPECT_FALSE(checkDepthImage(image, &why));
  image = depthImage(4, 3, "32FC1");
  image.height = 0xFFFFFFFFu;  // step * height needs 64 bits
  EXPECT_FALSE(checkDepthImage(image, &why));
  image = depthImage(4, 3, "32FC1");
  image.width = 0x40000001u;  // width * 4 wraps to 4 in 32 bits
  image.step = 16;
  EXPECT_FALSE(checkDepthImage(image, &why));
  EXPECT_FALSE(checkDepthImage(depthImage(0, 3, "32FC1"), &why));
  EXPECT_FALSE(checkDepthImage(depthImage(4, 3, "rgb8"), &why));
  EXPECT_NE(why.find("rgb8"), std::string::npos);
}

namespace {

sensor_msgs::LaserScan scan(std::size_t beams) {
  sensor_msgs::LaserScan s;
  s.angle_min = -1.0f;
  s.angle_increment = 0.01f;
  s.angle_max = s.angle_min + s.angle_increment * static_cast<float>(beams - 1);
  s.range_min = 0.1f;
  s.range_max = 10.0f;
  s.ranges.assign(beams, 2.0f);
  return s;
}

}  // namespace

TEST(CheckScan, RefusesInconsistentScans) {
  EXPECT_EQ(checkScan(scan(100)), "");
  sensor_msgs::LaserScan s = scan(100);
  s.angle_increment = 0.0f;
  EXPECT_NE(checkScan(s), "");
  s = scan(100);
  s.angle_increment = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(checkScan(s), "");
  s = scan(100);
  s.angle_max = 3.0f;  // implies ~400 beams
  EXPECT_NE(checkScan(s), "");
  s = scan(100);
  s.intensities.assign(99, 1.0f);
  EXPECT_NE(checkScan(s), "");
  s = scan(100);
  s.time_increment = std::numeric_limits<float>::infinity();
  EXPECT_NE(checkScan(s), "");
  s = scan(100);
  s.range_min = 20.0f;  // above range_max
  EXPECT_NE(checkScan(s), "");
  s = scan(1);
  s.ranges.clear();
  EXPECT_NE(checkScan(s), "");
}

TEST(CheckPose, RefusesNonFiniteAndZeroQuaternions) {
  geometry_msgs::PoseStamped p;
  p.header.frame_id = "map";
  p.pose.orientation.w = 1.0;
  EXPECT_EQ(checkPose(p), "");
  p.pose.position.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(checkPose(p), "");
  p.pose.position.x = 0.0;
  p.pose.orientation.w = 0.0;
  EXPECT_NE(checkPose(p), "");
  p.pose.orientation.w = 1.0;
  p.header.frame_id.clear();
  EXPECT_NE(checkPose(p), "");
}

TEST(PackedCloud, PacksPaddedRowsSoALinearWalkStaysInTheData) {
  const auto padded = boost::make_shared<sensor_msgs::PointCloud2>(xyziCloud(3, 2, 5));
  const sensor_msgs::PointCloud2ConstPtr packed = packedCloud(padded);
  ASSERT_EQ(checkCloudLayout(*packed), "");
  EXPECT_EQ(packed->row_step, 48u);
  EXPECT_EQ(packed->data.size(), 96u);  // a PointCloud2Iterator walks exactly 6 points
  std::vector<float> xs;
  forEachCloudPoint(*packed, 0, [&](float x, float, float) { xs.push_back(x); });
  EXPECT_EQ(xs, (std::vector<float>{0, 1, 2, 3, 4, 5}));
  const auto tight = boost::make_shared<sensor_msgs::PointCloud2>(xyziCloud(3, 2));
  EXPECT_EQ(packedCloud(tight).get(), tight.get());  // already packed: no copy
}

TEST(PackedCloud, AnEmptyCloudWithHugeHeightIsEmpty) {
  auto empty = boost::make_shared<sensor_msgs::PointCloud2>(xyziCloud(0, 1));
  empty->height = 0xFFFFFFFFu;  // rows of nothing: once a 4-billion-row loop
  empty->row_step = 0;
  ASSERT_EQ(checkCloudLayout(*empty), "");
  std::size_t visited = 0;
  forEachCloudPoint(*empty, 0, [&](float, float, float) { ++visited; });
  EXPECT_EQ(visited, 0u);
  EXPECT_EQ(packedCloud(empty)->height, 0u);
}

TEST(CheckScan, RefusesASweepLongerThanTenSeconds) {
  sensor_msgs::LaserScan s = scan(100);
  s.time_increment = 1e-4f;
  EXPECT_EQ(checkScan(s), "");
  s.time_increment = 1e18f;  // ros::Duration would throw from the callback
  EXPECT_NE(checkScan(s), "");
  s.time_increment = -2.0f;
  EXPECT_NE(checkScan(s), "");
}

TEST(CheckPose, RefusesAGoalBeyondAnyMap) {
  geometry_msgs::PoseStamped p;
  p.header.frame_id = "map";
  p.pose.orientation.w = 1.0;
  p.pose.position.x = 5e5;  // UTM easting: fine
  EXPECT_EQ(checkPose(p), "");
  p.pose.position.y = 1e300;
  EXPECT_NE(checkPose(p), "");
}

TEST(CheckOccupancyGrid, SizesAreComparedIn64Bits) {
  nav_msgs::OccupancyGrid grid;
  grid.info.resolution = 0.05f;
  grid.info.width = 3;
  grid.info.height = 2;
  grid.data.assign(6, 0);
  EXPECT_EQ(checkOccupancyGrid(grid), "");
  grid.data.pop_back();
  EXPECT_NE(checkOccupancyGrid(grid).find("data has 5 values"), std::string::npos);
  // 65536 x 65536 is 0 in 32 bits: an empty grid claiming 2^32 cells must not pass.
  grid.info.width = grid.info.height = 65536;
  grid.data.clear();
  EXPECT_NE(checkOccupancyGrid(grid), "");
  grid.info.width = grid.info.height = 0;
  EXPECT_EQ(checkOccupancyGrid(grid), "");  // an empty grid is consistent
  for (const float r : {0.0f, -0.1f, std::numeric_limits<float>::quiet_NaN()}) {
    grid.info.resolution = r;
    EXPECT_NE(checkOccupancyGrid(grid), "") << r;
  }
}
