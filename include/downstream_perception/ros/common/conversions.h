// Messages <-> the core's types, in one module (as grid_map_ros and voxblox_ros keep theirs):
// transforms as Eigen (one style for every nodelet and layer), the plane's yaw rotation of
// velocities and 2 x 2 covariances, tracked objects into another frame, and a grid's
// nav_msgs/MapMetaData. The message checks stay in message_checks.h.
#pragma once

#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/MapMetaData.h>
#include <ros/time.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <boost/array.hpp>

#include "downstream_perception/TrackedObject.h"
#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

/// The rigid transform of `t` (its quaternion normalized: a message's is only nearly unit).
Eigen::Isometry3d toEigen(const geometry_msgs::Transform& t);
/// The message of `T` (its rotation as a unit quaternion).
geometry_msgs::Transform toTransformMsg(const Eigen::Isometry3d& T);

/// The rotation matrix of `q` (normalized first: a message's quaternion is only nearly unit).
Eigen::Matrix3d rotationOf(const geometry_msgs::Quaternion& q);
/// Rotation about z of `q` (rad, in (-pi, pi]): the heading of a frame in the plane.
double yawOf(const geometry_msgs::Quaternion& q);
/// The plane's rotation by `yaw_rad`.
Eigen::Matrix2d yawRotation(double yaw_rad);

/// R S R^T of a row-major 2 x 2 covariance S (a track's position or velocity covariance).
void rotateCovariance(const Eigen::Matrix2d& R, boost::array<double, 4>* covariance);

/// The track through `transform` (target <- the track's frame, sampled at the track's stamp):
/// the position by the whole transform; velocity and the 2 x 2 covariances rotated by its yaw
/// (tracks live in the plane: R v, R S R^T).
TrackedObject transformTrack(const TrackedObject& in,
                             const geometry_msgs::TransformStamped& transform);

/// Size, resolution and origin (corner of cell (0, 0), at height z_m, not rotated) of `grid`:
/// shared by every OccupancyGrid the package publishes (the costmap, the TSDF slice), so they
/// agree on how a grid is described.
nav_msgs::MapMetaData mapMetaData(const GridGeometry& grid, double z_m, const ros::Time& load_time);

}  // namespace downstream_perception
