// The TSDF nodelet's parameters, read in one place: the map's TsdfConfig (names = its fields,
// units in the names), the nodelet's own settings and the OctoMap's. Validation of the map's
// config stays in the core (TsdfConfig::validate, OctreeConfig::validate).
#pragma once

#include <ros/node_handle.h>

#include <string>

#include "downstream_perception/core/tsdf/octree_worker.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "downstream_perception/ros/common/config_errors.h"

namespace downstream_perception {

/// Reads ~voxel_size_m, ~truncation_voxels, ... into a TsdfConfig. An invalid value (or an
/// invalid combination) is added to `errors` and the defaults are used for the whole config, so
/// a map is never built from half-valid settings.
TsdfConfig loadTsdfConfig(const ros::NodeHandle& pnh, ConfigErrorLog* errors);

/// The settings whose parameter type differs from the field's (the weighting and the edge guard's
/// rule by name, the block cap as an int), checked and stored into `c`. Empty on success, else the
/// reason (and `c` keeps its values). Shared by the start-up parameters and dynamic_reconfigure.
std::string setNamedTsdfSettings(const std::string& weighting, const std::string& edge_guard_rule,
                                 int max_blocks, TsdfConfig* c);

/// The nodelet's own settings beside the map's TsdfConfig (~mesh_rate_hz, ~health_period_s, the
/// slice, its window, ~tf_queue_size). Each invalid value is added to `errors` and its default
/// used.
struct TsdfNodeSettings {
  double mesh_rate_hz = 1.0;
  double health_period_s = 10.0;  ///< 0: no periodic health line
  TsdfSliceConfig slice;
  double slice_distance_max_m = 2.0;  ///< clearance cap of ~slice_distance (m); 0: off
  /// ~slice_window_m (side, m; 0: the blocks' whole extent) and ~slice_max_cells; the centre is
  /// the sensor's, set per frame.
  SliceWindow slice_window;
  double esdf_max_distance_m = 1.0;  ///< the ESDF's clamp (m); 0: no ESDF
  double esdf_slice_z_m = 1.0;       ///< height of ~esdf_slice (m, world_frame)
  int tf_queue_size = 10;
};
TsdfNodeSettings readTsdfNodeSettings(const ros::NodeHandle& pnh, ConfigErrorLog* errors);

/// The OctoMap's settings (~octomap_*): its range and distance bound are the map's (`map`).
/// octree.resolution_m == 0 turns the OctoMap off (nothing else is then checked).
struct OctomapSettings {
  OctreeConfig octree;
  int queue_size = 2;
  bool enabled() const { return octree.resolution_m > 0.0; }
};
OctomapSettings readOctomapSettings(const ros::NodeHandle& pnh, const TsdfConfig& map,
                                    ConfigErrorLog* errors);

}  // namespace downstream_perception
