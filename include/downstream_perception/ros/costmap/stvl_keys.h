// The spatio-temporal voxel layer's (STVL) keys, for an STVL configuration loaded as our
// VoxelObstacleLayer (`spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer` in a costmap's
// plugin list). Each STVL key is written under ours on the parameter server when ours is unset,
// so the layer and its dynamic_reconfigure server read one set of values; where the meaning
// differs, a WARN names the difference; every STVL key is declared known to the reader.
#pragma once

#include <ros/node_handle.h>

#include <string>
#include <vector>

namespace downstream_perception {

/// The plugin type STVL configurations name.
constexpr const char kStvlType[] = "spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer";

/// STVL's layer keys and its source keys that have no namesake here (declared known by the
/// layer's readers: adoptStvlKeys reads them).
const std::vector<std::string>& stvlLayerKeys();
const std::vector<std::string>& stvlSourceKeys();

/// Writes an STVL layer's keys under ours (where ours are unset), with STVL's defaults where the
/// YAML leaves them out: voxel_size (0.05 m) -> z_resolution (x, y are the costmap's
/// resolution_m: a WARN when they differ), a column up to max_obstacle_height (2 m) ->
/// z_voxels, voxel_decay / decay_model -> decay_time_s (ours is exponential: a WARN),
/// update_footprint_enabled -> footprint_clearing_enabled; per source: data_type PointCloud2,
/// max_z (10 m) -> raytrace_range of a clearing source; the frustum model, min_z, the voxel
/// filter, clear_after_reading false and mapping_mode are differences (a WARN each). Sets the
/// layer's `stvl_configuration` (true), which makes the layer read STVL's keys as its own (in any
/// other configuration they are unknown keys, warned as such). Returns the WARN texts (also
/// logged, prefixed by `who`).
std::vector<std::string> adoptStvlKeys(ros::NodeHandle& layer_nh, double costmap_resolution_m,
                                       const std::string& who);

}  // namespace downstream_perception
