// A 2-D slice of the TSDF for planning: every grid cell over which some observed voxel in a
// height band lies on or inside a surface is occupied (a table top within the robot's height
// reaches the costmap even though a 2-D lidar under it sees nothing), cells with only free
// voxels in the band are free, the rest unknown.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

struct TsdfSliceConfig {
  double min_z_m = 0.05;  ///< band bottom (map frame): above the floor
  double max_z_m = 1.8;   ///< band top: the robot's height
  /// A voxel whose signed distance is below this counts as occupied (m; negative = inside).
  /// Default: one voxel, so the surface shell itself is an obstacle.
  double occupied_distance_m = -1.0;  ///< < 0: use the voxel size
  std::string validate() const;
};

enum class SliceCell : std::int8_t { kUnknown = -1, kFree = 0, kOccupied = 1 };

struct TsdfSliceStats {
  std::size_t voxels_in_band = 0;
  std::size_t cells_occupied = 0;
  std::size_t cells_free = 0;
};

/// The voxel layers (z indices) whose centres, k * voxel_size_m, lie in [min_z_m, max_z_m]: the
/// band of the slice and of the band's ESDF (esdf_band.h). Empty when first > last.
struct VoxelLayers {
  int first = 0;
  int last = -1;
};
VoxelLayers bandLayers(double min_z_m, double max_z_m, double voxel_size_m);

/// A grid over the x-y extent of the allocated blocks with one cell per voxel column (voxel
/// centres in the middle of the cells). Invalid (0 x 0) for an empty map.
GridGeometry sliceGeometry(const TsdfMap& map);

/// The slice over `grid` (row-major, grid.index(x, y)); voxels are binned by their centre.
std::vector<SliceCell> sliceTsdf(const TsdfMap& map, const GridGeometry& grid,
                                 const TsdfSliceConfig& config, TsdfSliceStats* stats = nullptr);

/// Euclidean distance (m) from each cell's centre to the nearest occupied cell's centre (exact:
/// a separable distance transform over squared cell distances), 0 on occupied cells, capped at
/// max_distance_m, NaN on unknown cells (the distance does not see through them: it treats
/// them as free). For planners that want clearance rather than a binary obstacle map. Throws
/// std::invalid_argument when `cells` does not match `grid` or max_distance_m is outside
/// [0, 1e6] m (the distances are float32: a larger cap would come out as +Inf).
std::vector<float> sliceDistance(const std::vector<SliceCell>& cells, const GridGeometry& grid,
                                 double max_distance_m);

}  // namespace downstream_perception
