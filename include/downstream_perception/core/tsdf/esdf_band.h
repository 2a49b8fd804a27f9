// The ESDF of a height band, in 2-D: the clearance a ground robot whose body spans the band
// (slice_min_z_m .. slice_max_z_m) has at each voxel column. It is the ESDF's own mechanism
// restricted to the band, not a second one: the same voxel states (esdfStateOf: unknown at
// weight <= min_weight, occupied at D < 0, else free), the same exact bounded transform
// (boundedSquaredDistances3d, here one layer deep) and the same values (esdfMetres:
// (sqrt(k) - 1/2) * voxel size, negative inside, clamped). Only the seeds differ: a column is
// occupied when any voxel of the band over it is occupied, free when it has a free band voxel
// and no occupied one, unknown otherwise. So the floor under the band, and anything above it,
// is no obstacle (the 3-D ESDF's minimum over the band would read the floor's few centimetres
// everywhere). For a free column with every band voxel known this is exactly the minimum over
// the band's layers of the 3-D ESDF seeded by the band's occupied voxels alone.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

struct EsdfBandConfig {
  double min_z_m = 0.05;        ///< band bottom (map frame, m): above the floor
  double max_z_m = 1.8;         ///< band top (m): the robot's height
  double max_distance_m = 2.0;  ///< clamp of the distances (m)
  /// The cells to compute (sliceWindowGeometry's window); none: sliceGeometry(map), the blocks'
  /// whole extent. It must lie on the voxel lattice (one cell per voxel column, voxel centres in
  /// the middle). Obstacles up to max_distance_m outside it are still seen: the transform runs
  /// over the grid grown by that much (within the blocks' extent) and is cropped, so the values
  /// inside equal the whole map's.
  std::optional<GridGeometry> grid;
  /// At most this many columns computed (the grid and its padding; 0: no bound). The padding
  /// alone can hold far more than the grid: a 2,000^2 window with a 100 m cap at 2 cm pads
  /// 5,000 columns on each side, 144 M columns (1.3 GB). Over the bound the padding is narrowed
  /// (EsdfBandStats::padding_cut): obstacles beyond it are then not seen, so a cell nearer the
  /// grid's edge than the cap may read farther than in the whole map. The grid itself is always
  /// computed (bound it with its own size).
  std::size_t max_computed_columns = 0;
  /// Empty if valid for voxels of voxel_size_m, else the reason: finite min_z_m < max_z_m;
  /// max_distance_m finite, at least one voxel (as the ESDF's: a smaller cap would clamp every
  /// value, even the half voxel next to an obstacle) and at most kMaxDistanceM; a grid on the
  /// lattice (or empty: no cells).
  std::string validate(double voxel_size_m) const;
  static constexpr double kMaxDistanceM = 1e6;  ///< distances are float32
};

struct EsdfBandStats {
  std::size_t columns_occupied = 0;
  std::size_t columns_free = 0;
  std::size_t voxels_in_band = 0;  ///< known voxels of the band over the grid's columns
  /// Columns the transform ran over: the grid grown by the cap (the padding), within the
  /// blocks' extent. Its working memory is kBytesPerComputedCell per such column.
  std::size_t columns_computed = 0;
  std::size_t padding_voxels = 0;  ///< columns computed beyond the grid on each side
  bool padding_cut = false;        ///< narrowed below the cap to fit max_computed_columns
  /// Labels (1 byte), squared distances and the transform's scratch (4 + 4); the result's float
  /// (4 bytes) per cell of the grid comes on top.
  static constexpr std::size_t kBytesPerComputedCell = 9;
};

struct EsdfBandSlice {
  /// config.grid, else sliceGeometry(map): one cell per voxel column, the same cells as
  /// sliceTsdf's over that grid.
  GridGeometry grid;
  /// Row-major over `grid` (m): > 0 free (distance to the nearest occupied column), < 0
  /// occupied (to the nearest free column), NaN unknown; magnitudes clamped at max_distance_m.
  std::vector<float> distance_m;
  EsdfBandStats stats;
};

/// The band's 2-D ESDF over config.grid, else over sliceGeometry(map) (an empty grid for an empty
/// map). Throws std::invalid_argument if config.validate(map.voxelSize()) fails or, without a
/// grid, the map's x-y extent fits no GridGeometry (sliceGeometry's limits).
EsdfBandSlice esdfBandSlice(const TsdfMap& map, const EsdfBandConfig& config);

}  // namespace downstream_perception
