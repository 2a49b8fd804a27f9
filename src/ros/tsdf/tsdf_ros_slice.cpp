// TsdfRos's slice (issue 22): the window around the sensor, ~slice and its clearance
// (~slice_distance, the band's ESDF over the same grid).
#include "downstream_perception/ros/tsdf/tsdf_ros.h"

#include <chrono>

#include "downstream_perception/core/tsdf/esdf_band.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "downstream_perception/ros/tsdf/tsdf_slice_messages.h"

namespace downstream_perception {

void TsdfRos::setSensorLocked(const Eigen::Isometry3d& T_world_sensor) {
  sensor_xy_ = T_world_sensor.translation().head<2>();
  sensor_known_ = true;
}

GridGeometry TsdfRos::sliceGridLocked() {
  const ColumnBox columns = blockColumns(*map_);
  SliceWindow window = slice_window_;
  const double s = map_->voxelSize();
  // Blocks come from integrated frames, so the sensor is known whenever there are any; the
  // blocks' middle only covers a map filled some other way.
  const Eigen::Vector2d centre =
      sensor_known_ ? sensor_xy_
                    : Eigen::Vector2d(0.5 * static_cast<double>(columns.min_x + columns.max_x) * s,
                                      0.5 * static_cast<double>(columns.min_y + columns.max_y) * s);
  window.centre_x_m = centre.x();
  window.centre_y_m = centre.y();
  bool capped = false;
  const GridGeometry grid = sliceWindowGeometry(columns, s, window, &capped);
  if (capped) {
    ++slices_capped_;
    ROS_WARN_THROTTLE(10.0,
                      "tsdf: the slice over %.0f x %.0f m exceeds ~slice_max_cells = %zu: cut to "
                      "%d x %d cells around the sensor (set ~slice_window_m to bound it on "
                      "purpose)",
                      static_cast<double>(columns.width()) * s,
                      static_cast<double>(columns.height()) * s, window.max_cells, grid.sizeX(),
                      grid.sizeY());
  }
  return grid;
}

void TsdfRos::sliceLocked(const std_msgs::Header& header, nav_msgs::OccupancyGridPtr* slice,
                          sensor_msgs::PointCloud2Ptr* distance) {
  slice_changed_ = false;
  const auto t0 = std::chrono::steady_clock::now();
  GridGeometry grid;
  try {
    grid = sliceGridLocked();
  } catch (const std::invalid_argument& error) {
    // Kept as a guard: the window and its cap keep every grid within GridGeometry's limits.
    ++slices_refused_;
    ROS_WARN_THROTTLE(10.0, "tsdf: no slice this tick: %s", error.what());
    return;
  }
  std::vector<SliceCell> cells;
  if (grid.sizeX() > 0) cells = sliceTsdf(*map_, grid, slice_, &slice_stats_);
  slice_cells_ = grid.cellCount();
  *slice = sliceGridMessage(cells, grid, slice_.min_z_m, header);
  // The clearance only while someone listens (latched: a late subscriber gets the next): the
  // band's ESDF over the slice's cells (esdf_band.h), not a second distance mechanism. It sees
  // obstacles up to its cap outside the window, so its values there are the whole map's, unless
  // that padding would pass twice ~slice_max_cells (a long cap at fine voxels): then it is
  // narrowed, and counted.
  slice_distance_stats_ = EsdfBandStats{};  // nothing computed, nothing held, unless below
  if (slice_distance_publisher_ && slice_distance_publisher_.getNumSubscribers() > 0) {
    EsdfBandConfig band;
    band.min_z_m = slice_.min_z_m;
    band.max_z_m = slice_.max_z_m;
    band.max_distance_m = slice_distance_max_m_;
    band.grid = grid;
    band.max_computed_columns = kClearanceColumnsPerSliceCell * slice_window_.max_cells;
    const EsdfBandSlice clearance = esdfBandSlice(*map_, band);
    slice_distance_stats_ = clearance.stats;
    if (clearance.stats.padding_cut) {
      ++clearance_padding_cuts_;
      ROS_WARN_THROTTLE(10.0,
                        "tsdf: the clearance's padding (~slice_distance_max_m %.2f m beyond the "
                        "window) was narrowed to %zu voxels to stay within %zu columns: near the "
                        "window's edge it may read farther than the map's",
                        slice_distance_max_m_, clearance.stats.padding_voxels,
                        band.max_computed_columns);
    }
    *distance = sliceDistanceCloud(clearance.distance_m, clearance.grid, band.min_z_m, header);
  }
  slice_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace downstream_perception
