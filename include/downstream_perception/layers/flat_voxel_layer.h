// downstream_perception/FlatVoxelLayer: the log-odds obstacle layer configured with
// costmap_2d::VoxelLayer's keys. The voxel column (origin_z, z_resolution, z_voxels) becomes the
// marking height band (its top intersected with max_obstacle_height); mark_threshold,
// unknown_threshold and publish_voxel_map keep costmap_2d's default behaviour and are named as
// unsupported otherwise. Clearing stays 2-D: a real 3-D voxel layer is a later issue.
#pragma once

#include "downstream_perception/layers/log_odds_obstacle_layer.h"

namespace downstream_perception {

/// costmap_2d::VoxelLayer's keys (VoxelPlugin.cfg defaults), read at start-up.
struct VoxelColumnConfig {
  double origin_z = 0.0;      ///< m
  double z_resolution = 0.2;  ///< m per voxel
  int z_voxels = 10;          ///< voxels per column, at most 16
  int unknown_threshold = 15;
  int mark_threshold = 0;
  bool publish_voxel_map = false;

  /// Empty if valid (z_resolution > 0 and finite, z_voxels in [1, 16], origin_z finite).
  std::string validate() const;
  /// m: the column's top, above which costmap_2d's VoxelLayer marks nothing.
  double topZ() const { return origin_z + z_voxels * z_resolution; }
  /// Whether a flat column reproduces costmap_2d's result: any mark shows (mark_threshold 0) and
  /// no cleared column stays unknown (unknown_threshold >= z_voxels).
  bool markThresholdIsDefault() const { return mark_threshold == 0; }
  bool unknownThresholdIsDefault() const { return unknown_threshold >= z_voxels; }
};

class FlatVoxelLayer : public LogOddsObstacleLayer {
 protected:
  void readLayerParams(ParamReader& reader) override;
};

}  // namespace downstream_perception
