// A 2-D slice of the TSDF for planning: every grid cell over which some observed voxel in a
// height band lies on or inside a surface is occupied (a table top within the robot's height
// reaches the costmap even though a 2-D lidar under it sees nothing), cells with only free
// voxels in the band are free, the rest unknown.
#pragma once

#include <algorithm>
#include <cstddef>
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

/// The voxel columns (x, y lattice indices: column i holds the voxels whose centres have x = i *
/// voxel) under the allocated blocks, in 64 bits (block keys times 16 need not fit an int).
/// Empty for an empty map.
struct ColumnBox {
  std::int64_t min_x = 0;
  std::int64_t min_y = 0;
  std::int64_t max_x = -1;
  std::int64_t max_y = -1;
  bool empty() const { return min_x > max_x || min_y > max_y; }
  std::int64_t width() const { return empty() ? 0 : max_x - min_x + 1; }
  std::int64_t height() const { return empty() ? 0 : max_y - min_y + 1; }
  ColumnBox intersected(const ColumnBox& o) const {
    return {std::max(min_x, o.min_x), std::max(min_y, o.min_y), std::min(max_x, o.max_x),
            std::min(max_y, o.max_y)};
  }
  /// The smallest box holding both (an empty one adds nothing).
  ColumnBox hull(const ColumnBox& o) const {
    if (o.empty()) return *this;
    if (empty()) return o;
    return {std::min(min_x, o.min_x), std::min(min_y, o.min_y), std::max(max_x, o.max_x),
            std::max(max_y, o.max_y)};
  }
  ColumnBox grown(std::int64_t by) const {
    return {min_x - by, min_y - by, max_x + by, max_y + by};
  }
};
ColumnBox blockColumns(const TsdfMap& map);

/// Where the slice is taken: a square window around the sensor, bounded in cells.
struct SliceWindow {
  double centre_x_m = 0.0;  ///< the sensor's latest position (map frame)
  double centre_y_m = 0.0;
  double side_m = 0.0;  ///< 0: the blocks' whole extent
  /// Hard cap: a slice of more cells is cut to the square of floor(sqrt(max_cells)) columns
  /// around the centre, so its memory is bounded whatever the map's extent and side_m.
  std::size_t max_cells = kDefaultMaxCells;
  static constexpr std::size_t kDefaultMaxCells = 4000000;  ///< 2,000^2: 100 m at 5 cm
  /// Empty if valid, else the reason: side_m finite, in [0, kMaxSideM]; max_cells in [1,
  /// GridGeometry::kMaxCells].
  std::string validate() const;
  static constexpr double kMaxSideM = 1e5;
};

/// The slice's grid for `window` over `columns` (blockColumns): the square of round(side /
/// voxel) columns whose middle column (index n / 2) is the one holding the centre, so the grid
/// moves in whole voxels and does not shimmer; intersected with `columns`; cut to the cap (see
/// SliceWindow::max_cells) when larger. Cells as sliceGeometry's (one per voxel column, voxel
/// centres in the middle). An invalid (0 x 0) grid when the window misses the blocks. *capped
/// (optional) says whether the cap cut it. Throws std::invalid_argument on an invalid window.
GridGeometry sliceWindowGeometry(const ColumnBox& columns, double voxel_size_m,
                                 const SliceWindow& window, bool* capped = nullptr);

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
