// 3-D points (a sensor_msgs/PointCloud2 from a depth camera or 3-D lidar) turned into 2-D beams
// for the log-odds obstacle layer, with costmap_2d's height band semantics.
//
// Each point is placed in the grid's frame with the sensor's pose at the cloud's stamp. Points
// whose height z (in the grid's frame) lies outside [min_obstacle_height, max_obstacle_height]
// are skipped entirely: they neither mark nor clear (the floor and the ceiling are not
// obstacles, and a ray to them says nothing about the obstacle band). A point inside the band
// is a return at its horizontal distance from the sensor origin: it marks the cell containing it
// within obstacle_max_range and clears from the sensor to it, like a laser beam; a point straight
// above or below the sensor (zero horizontal range) marks the sensor's own cell and clears
// nothing, as costmap_2d marks it. Non-finite points
// (NaN from depth holes) are invalid and ignored. With a merge grid only the first point per
// cell of that grid casts a beam: the same cells are marked, and the clearing rays differ from
// the per-point ones only within that cell's width at the far end.
#pragma once

#include <Eigen/Geometry>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

struct CloudBeamsConfig {
  double min_obstacle_height = 0.0;  ///< m, in the grid's frame
  double max_obstacle_height = 2.0;  ///< m, in the grid's frame
  /// The grid the beams are integrated into, if set: points in the same cell of it give one beam
  /// (a depth camera puts hundreds of pixels into one grid cell; their rays are the same to a
  /// cell). Unset = one beam per point. The cells are the grid's own (GridGeometry's lattice, so
  /// any rolling-window shift of the same grid gives the same cells): squares of the resolution
  /// counted from the world origin instead would put two points of neighbouring cells into one
  /// square whenever the origin is not a multiple of the resolution, and leave one cell unmarked.
  std::optional<GridGeometry> merge_grid;

  /// Empty if valid, else the reason.
  std::string validate() const;
};

/// Appends one beam per usable point. `xyz` points at the first point's x; y and z follow it as
/// consecutive floats; successive points are `stride_bytes` apart (PointCloud2's point_step).
/// `grid_from_sensor` places sensor-frame points in the grid's frame; its translation is the ray
/// origin.
void beamsFromCloud(const ScanIntegrator& integrator, const CloudBeamsConfig& config,
                    const unsigned char* xyz, std::size_t count, std::size_t stride_bytes,
                    const Eigen::Isometry3d& grid_from_sensor, std::vector<BeamUpdate>* beams,
                    IntegrationStats* stats);

}  // namespace downstream_perception
