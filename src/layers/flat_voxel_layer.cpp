#include "downstream_perception/layers/flat_voxel_layer.h"

#include <pluginlib/class_list_macros.hpp>

#include <ros/console.h>

#include <cmath>
#include <sstream>

namespace downstream_perception {

std::string VoxelColumnConfig::validate() const {
  std::ostringstream why;
  if (!std::isfinite(origin_z)) {
    why << "origin_z must be finite, got " << origin_z;
  } else if (!std::isfinite(z_resolution) || z_resolution <= 0.0) {
    why << "z_resolution must be finite and > 0 m, got " << z_resolution;
  } else if (z_voxels < 1 || z_voxels > 16) {
    why << "z_voxels must be in [1, 16], got " << z_voxels;
  }
  return why.str();
}

void FlatVoxelLayer::readLayerParams(ParamReader& reader) {
  VoxelColumnConfig column;
  reader.get("origin_z", &column.origin_z);
  reader.get("z_resolution", &column.z_resolution);
  reader.get("z_voxels", &column.z_voxels);
  reader.get("unknown_threshold", &column.unknown_threshold);
  reader.get("mark_threshold", &column.mark_threshold);
  reader.get("publish_voxel_map", &column.publish_voxel_map);
  const std::string why = column.validate();
  if (!why.empty()) {
    warnParam("voxel column invalid (" + why + "); using costmap_2d's defaults");
    column = VoxelColumnConfig();
  }
  // Points below origin_z still mark in costmap_2d (they go into the lowest voxel); points at
  // or above the column's top never do.
  extra_mark_limit_z_ = column.topZ();
  const std::string later = "a real 3-D voxel layer is a later issue";
  if (!column.markThresholdIsDefault()) {
    reader.unsupported("mark_threshold",
                       "a flat layer keeps no voxels to count: any mark in a column marks the "
                       "cell, as mark_threshold 0 does (" +
                           later + ")");
  }
  if (!column.unknownThresholdIsDefault()) {
    reader.unsupported("unknown_threshold",
                       "a flat layer keeps no voxels to count: a cleared cell is free, as with "
                       "unknown_threshold >= z_voxels (" +
                           later + ")");
  }
  if (column.publish_voxel_map) {
    reader.unsupported("publish_voxel_map", "there is no voxel grid to publish (" + later + ")");
  }
  std::ostringstream flat;
  flat << "costmap_2d::VoxelLayer keys read: marking up to " << column.topZ() << " m (origin_z "
       << column.origin_z << " + z_voxels " << column.z_voxels << " x z_resolution "
       << column.z_resolution
       << "), start-up only (not in dynamic_reconfigure). Difference: clearing is 2-D, each ray "
          "clears the cells it crosses whatever its height, where costmap_2d raytraces through "
          "voxels in 3-D ("
       << later << ")";
  // Said once, in the log only: a difference by design, not a fault of this configuration.
  ROS_WARN("layer '%s': %s", name_.c_str(), flat.str().c_str());
}

}  // namespace downstream_perception

PLUGINLIB_EXPORT_CLASS(downstream_perception::FlatVoxelLayer, downstream_perception::Layer)
