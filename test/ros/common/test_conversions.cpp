// The ROS conversion module: transforms, the plane's covariance rotation, tracks into another
// frame and a grid's MapMetaData, with exact expected numbers (no master needed).
#include <gtest/gtest.h>

#include <cmath>

#include "downstream_perception/ros/common/conversions.h"

namespace downstream_perception {
namespace {

constexpr double kEps = 1e-12;

geometry_msgs::Quaternion yawQuaternion(double yaw) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(yaw / 2.0);
  q.w = std::cos(yaw / 2.0);
  return q;
}

TEST(Conversions, NinetyDegreeYawSwapsADiagonalCovariance) {
  boost::array<double, 4> cov{{1.0, 0.0, 0.0, 4.0}};  // diag(1, 4), row-major
  rotateCovariance(yawRotation(M_PI / 2.0), &cov);
  EXPECT_NEAR(cov[0], 4.0, kEps);
  EXPECT_NEAR(cov[1], 0.0, kEps);
  EXPECT_NEAR(cov[2], 0.0, kEps);
  EXPECT_NEAR(cov[3], 1.0, kEps);
}

TEST(Conversions, FortyFiveDegreeYawCouplesTheAxes) {
  // R diag(1, 4) R^T at 45 deg: [[2.5, -1.5], [-1.5, 2.5]].
  boost::array<double, 4> cov{{1.0, 0.0, 0.0, 4.0}};
  rotateCovariance(yawRotation(M_PI / 4.0), &cov);
  EXPECT_NEAR(cov[0], 2.5, kEps);
  EXPECT_NEAR(cov[1], -1.5, kEps);
  EXPECT_NEAR(cov[2], -1.5, kEps);
  EXPECT_NEAR(cov[3], 2.5, kEps);
}

TEST(Conversions, YawOfAQuaternion) {
  EXPECT_NEAR(yawOf(yawQuaternion(0.3)), 0.3, kEps);
  EXPECT_NEAR(yawOf(yawQuaternion(-2.0)), -2.0, kEps);
}

TEST(Conversions, RotationOfANearlyUnitQuaternionIsARotation) {
  // 90 deg about z, scaled by 1.01 (a message's quaternion is only nearly unit): x -> y exactly,
  // and the matrix stays orthonormal (tf2::Matrix3x3 and Eigen both normalize; we rely on it).
  geometry_msgs::Quaternion q = yawQuaternion(M_PI / 2.0);
  q.z *= 1.01;
  q.w *= 1.01;
  const Eigen::Matrix3d r = rotationOf(q);
  EXPECT_NEAR(r(0, 0), 0.0, kEps);
  EXPECT_NEAR(r(1, 0), 1.0, kEps);
  EXPECT_NEAR(r(2, 2), 1.0, kEps);
  EXPECT_NEAR((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, kEps);
}

TEST(Conversions, RotationOfARollTiltsTheZAxis) {
  // 180 deg about x (a scanner mounted upside down): z -> -z, the test the scan source uses.
  geometry_msgs::Quaternion q;
  q.x = 1.0;
  q.w = 0.0;
  const Eigen::Matrix3d r = rotationOf(q);
  EXPECT_NEAR(r(2, 2), -1.0, kEps);
  EXPECT_NEAR(r(1, 1), -1.0, kEps);
  EXPECT_NEAR(r(0, 0), 1.0, kEps);
}

TEST(Conversions, TransformRoundTripsThroughEigen) {
  geometry_msgs::Transform t;
  t.translation.x = 1.5;
  t.translation.y = -2.0;
  t.translation.z = 0.25;
  t.rotation = yawQuaternion(M_PI / 2.0);
  const Eigen::Isometry3d T = toEigen(t);
  // 90 deg about z: x -> y; then the translation.
  const Eigen::Vector3d p = T * Eigen::Vector3d(1.0, 0.0, 0.0);
  EXPECT_NEAR(p.x(), 1.5, kEps);
  EXPECT_NEAR(p.y(), -1.0, kEps);
  EXPECT_NEAR(p.z(), 0.25, kEps);
  const geometry_msgs::Transform back = toTransformMsg(T);
  EXPECT_NEAR(back.translation.x, 1.5, kEps);
  EXPECT_NEAR(back.translation.y, -2.0, kEps);
  EXPECT_NEAR(back.translation.z, 0.25, kEps);
  EXPECT_NEAR(back.rotation.x, 0.0, kEps);
  EXPECT_NEAR(back.rotation.y, 0.0, kEps);
  EXPECT_NEAR(back.rotation.z, t.rotation.z, kEps);
  EXPECT_NEAR(back.rotation.w, t.rotation.w, kEps);
}

TEST(Conversions, ANonUnitQuaternionIsNormalized) {
  geometry_msgs::Transform t;
  t.rotation.w = 2.0;  // identity, scaled
  const Eigen::Isometry3d T = toEigen(t);
  EXPECT_TRUE(T.linear().isApprox(Eigen::Matrix3d::Identity(), kEps));
}

TEST(Conversions, TrackIntoAFrameTurnedByNinetyDegrees) {
  TrackedObject track;
  track.position.x = 1.0;
  track.position.y = 0.0;
  track.velocity.x = 2.0;
  track.velocity.y = 0.0;
  track.position_covariance = {{1.0, 0.0, 0.0, 4.0}};
  track.velocity_covariance = {{9.0, 0.0, 0.0, 1.0}};
  geometry_msgs::TransformStamped transform;
  transform.transform.translation.x = 10.0;
  transform.transform.rotation = yawQuaternion(M_PI / 2.0);
  const TrackedObject out = transformTrack(track, transform);
  EXPECT_NEAR(out.position.x, 10.0, kEps);
  EXPECT_NEAR(out.position.y, 1.0, kEps);
  EXPECT_NEAR(out.velocity.x, 0.0, kEps);
  EXPECT_NEAR(out.velocity.y, 2.0, kEps);
  EXPECT_NEAR(out.position_covariance[0], 4.0, kEps);
  EXPECT_NEAR(out.position_covariance[3], 1.0, kEps);
  EXPECT_NEAR(out.velocity_covariance[0], 1.0, kEps);
  EXPECT_NEAR(out.velocity_covariance[3], 9.0, kEps);
}

TEST(Conversions, MapMetaDataOfAGrid) {
  const GridGeometry grid(40, 30, 0.05, -1.0, 2.0);
  const nav_msgs::MapMetaData info = mapMetaData(grid, 0.5, ros::Time(7, 0));
  EXPECT_EQ(info.width, 40u);
  EXPECT_EQ(info.height, 30u);
  EXPECT_FLOAT_EQ(info.resolution, 0.05f);
  EXPECT_DOUBLE_EQ(info.origin.position.x, -1.0);
  EXPECT_DOUBLE_EQ(info.origin.position.y, 2.0);
  EXPECT_DOUBLE_EQ(info.origin.position.z, 0.5);
  EXPECT_DOUBLE_EQ(info.origin.orientation.w, 1.0);
  EXPECT_EQ(info.map_load_time, ros::Time(7, 0));
}

}  // namespace
}  // namespace downstream_perception
