#include "downstream_perception/core/tsdf/tsdf_slice.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/costmap/inflation.h"

namespace downstream_perception {

std::string TsdfSliceConfig::validate() const {
  std::ostringstream why;
  if (!(std::isfinite(min_z_m) && std::isfinite(max_z_m) && min_z_m < max_z_m)) {
    why << "need finite min_z_m < max_z_m, got " << min_z_m << " and " << max_z_m;
  } else if (!std::isfinite(occupied_distance_m)) {
    why << "occupied_distance_m must be finite";
  }
  return why.str();
}

VoxelLayers bandLayers(double min_z_m, double max_z_m, double voxel_size_m) {
  return {static_cast<int>(std::ceil(min_z_m / voxel_size_m)),
          static_cast<int>(std::floor(max_z_m / voxel_size_m))};
}

ColumnBox blockColumns(const TsdfMap& map) {
  ColumnBox box;
  if (map.blockCount() == 0) return box;
  box.min_x = box.min_y = std::numeric_limits<std::int64_t>::max();
  box.max_x = box.max_y = std::numeric_limits<std::int64_t>::min();
  for (const auto& kv : map.blocks()) {
    const std::int64_t x = std::int64_t{kv.first.x()} * kTsdfBlockSide;
    const std::int64_t y = std::int64_t{kv.first.y()} * kTsdfBlockSide;
    box.min_x = std::min(box.min_x, x);
    box.min_y = std::min(box.min_y, y);
    box.max_x = std::max(box.max_x, x + kTsdfBlockSide - 1);
    box.max_y = std::max(box.max_y, y + kTsdfBlockSide - 1);
  }
  return box;
}

namespace {

/// One cell per column of `box` (voxel centres in the middle of the cells); invalid (0 x 0) for
/// an empty box. GridGeometry refuses (throws) a box beyond its per-axis and total limits.
GridGeometry columnGrid(const ColumnBox& box, double voxel_size_m) {
  if (box.empty()) return GridGeometry();
  return GridGeometry(
      static_cast<int>(std::min<std::int64_t>(box.width(), std::numeric_limits<int>::max())),
      static_cast<int>(std::min<std::int64_t>(box.height(), std::numeric_limits<int>::max())),
      voxel_size_m, (static_cast<double>(box.min_x) - 0.5) * voxel_size_m,
      (static_cast<double>(box.min_y) - 0.5) * voxel_size_m);
}

}  // namespace

GridGeometry sliceGeometry(const TsdfMap& map) {
  return columnGrid(blockColumns(map), map.voxelSize());
}

std::string SliceWindow::validate() const {
  std::ostringstream why;
  if (!(std::isfinite(centre_x_m) && std::isfinite(centre_y_m))) {
    why << "the window's centre must be finite, got " << centre_x_m << ", " << centre_y_m;
  } else if (!(std::isfinite(side_m) && side_m >= 0.0 && side_m <= kMaxSideM)) {
    why << "side_m must be in [0, " << kMaxSideM << "] m (0 = the whole extent), got " << side_m;
  } else if (max_cells < 1 || max_cells > GridGeometry::kMaxCells) {
    why << "max_cells must be in [1, " << GridGeometry::kMaxCells << "], got " << max_cells;
  }
  return why.str();
}

namespace {

/// n x n columns whose index n / 2 holds the point (cx, cy): the nearest column centre, so the
/// square moves in whole voxels as the point moves.
ColumnBox squareAround(double cx, double cy, double voxel, std::int64_t n) {
  // Far beyond any TSDF index (int block keys), yet safe to convert.
  constexpr double kFar = 1e15;
  const auto column = [&](double c) {
    return static_cast<std::int64_t>(std::clamp(std::floor(c / voxel + 0.5), -kFar, kFar));
  };
  ColumnBox box;
  box.min_x = column(cx) - n / 2;
  box.min_y = column(cy) - n / 2;
  box.max_x = box.min_x + n - 1;
  box.max_y = box.min_y + n - 1;
  return box;
}

/// Whether a grid over `box` stays within max_cells (and GridGeometry's per-axis limit).
bool fits(const ColumnBox& box, std::size_t max_cells) {
  const std::int64_t w = box.width();
  const std::int64_t h = box.height();
  if (w > GridGeometry::kMaxCellsPerAxis || h > GridGeometry::kMaxCellsPerAxis) return false;
  return static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h) <= max_cells;
}

/// floor(sqrt(n)), exact (the double's root may be one off for large n).
std::int64_t integerSqrt(std::size_t n) {
  auto r = static_cast<std::int64_t>(std::sqrt(static_cast<double>(n)));
  while (r > 0 && static_cast<std::uint64_t>(r) * r > n) --r;
  while (static_cast<std::uint64_t>(r + 1) * (r + 1) <= n) ++r;
  return r;
}

}  // namespace

GridGeometry sliceWindowGeometry(const ColumnBox& columns, double voxel_size_m,
                                 const SliceWindow& window, bool* capped) {
  const std::string why = window.validate();
  if (!why.empty()) throw std::invalid_argument("slice window: " + why);
  if (!(std::isfinite(voxel_size_m) && voxel_size_m > 0.0)) {
    throw std::invalid_argument("slice window: the voxel size must be > 0");
  }
  if (capped != nullptr) *capped = false;
  ColumnBox box = columns;
  if (window.side_m > 0.0) {
    const auto n = std::max<std::int64_t>(1, std::llround(window.side_m / voxel_size_m));
    box = box.intersected(squareAround(window.centre_x_m, window.centre_y_m, voxel_size_m, n));
  }
  if (!box.empty() && !fits(box, window.max_cells)) {
    // Cut, not refused: the planner keeps its surroundings however far the map reaches.
    const std::int64_t n =
        std::min<std::int64_t>(integerSqrt(window.max_cells), GridGeometry::kMaxCellsPerAxis);
    box = box.intersected(squareAround(window.centre_x_m, window.centre_y_m, voxel_size_m, n));
    if (capped != nullptr) *capped = true;
  }
  return columnGrid(box, voxel_size_m);
}

std::vector<SliceCell> sliceTsdf(const TsdfMap& map, const GridGeometry& grid,
                                 const TsdfSliceConfig& config, TsdfSliceStats* stats) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("tsdf slice: " + why);
  std::vector<SliceCell> cells(static_cast<std::size_t>(grid.sizeX()) * grid.sizeY(),
                               SliceCell::kUnknown);
  TsdfSliceStats local;
  const double s = map.voxelSize();
  const double mu = map.config().truncation();
  const float min_weight = static_cast<float>(map.config().min_weight);
  const float occupied_below =
      static_cast<float>((config.occupied_distance_m < 0.0 ? s : config.occupied_distance_m) / mu);
  const VoxelLayers layers = bandLayers(config.min_z_m, config.max_z_m, s);
  const int k_min = layers.first;
  const int k_max = layers.last;
  // A window over a wide map: whole blocks outside the grid (by more than a voxel, so the
  // per-voxel test below decides every voxel near its edge) are skipped unread.
  const double x_lo = grid.originX() - s, x_hi = grid.originX() + grid.sizeXMetres() + s;
  const double y_lo = grid.originY() - s, y_hi = grid.originY() + grid.sizeYMetres() + s;
  const double block_m = kTsdfBlockSide * s;
  for (const auto& [key, block] : map.blocks()) {
    const int z0 = key.z() * kTsdfBlockSide;
    if (z0 + kTsdfBlockSide - 1 < k_min || z0 > k_max) continue;
    const double bx = static_cast<double>(key.x()) * block_m;
    const double by = static_cast<double>(key.y()) * block_m;
    if (bx + block_m < x_lo || bx > x_hi || by + block_m < y_lo || by > y_hi) continue;
    for (int z = std::max(0, k_min - z0); z < kTsdfBlockSide && z0 + z <= k_max; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const TsdfVoxel& v = block->voxels[TsdfBlock::linear(x, y, z)];
          if (!(v.observedWeight() > min_weight)) continue;
          // Voxel centres often lie exactly on cell edges (same resolution, origin on the
          // lattice); a nudge of 1e-4 voxel breaks the tie the same way for every voxel, so no
          // cell is skipped through rounding.
          const double wx = (key.x() * kTsdfBlockSide + x) * s + 1e-4 * s;
          const double wy = (key.y() * kTsdfBlockSide + y) * s + 1e-4 * s;
          const CellIndex c = grid.worldToCellUnbounded(wx, wy);
          if (!grid.inBounds(c.x, c.y)) continue;
          ++local.voxels_in_band;
          SliceCell& cell = cells[grid.index(c.x, c.y)];
          if (v.distance < occupied_below) {
            cell = SliceCell::kOccupied;
          } else if (cell == SliceCell::kUnknown) {
            cell = SliceCell::kFree;
          }
        }
      }
    }
  }
  for (const SliceCell c : cells) {
    local.cells_occupied += c == SliceCell::kOccupied;
    local.cells_free += c == SliceCell::kFree;
  }
  if (stats != nullptr) *stats = local;
  return cells;
}

std::vector<float> sliceDistance(const std::vector<SliceCell>& cells, const GridGeometry& grid,
                                 double max_distance_m) {
  const std::size_t n = static_cast<std::size_t>(grid.sizeX()) * grid.sizeY();
  if (cells.size() != n) {
    throw std::invalid_argument("slice distance: " + std::to_string(cells.size()) +
                                " cells for a grid of " + std::to_string(n));
  }
  if (!(max_distance_m >= 0.0 && max_distance_m <= 1e6)) {  // distances are float32
    throw std::invalid_argument("slice distance: max_distance_m must be in [0, 1e6] m, got " +
                                std::to_string(max_distance_m));
  }
  std::vector<float> distance(n, std::numeric_limits<float>::quiet_NaN());
  if (n == 0) return distance;
  std::vector<std::uint8_t> occupied(n);
  std::transform(cells.begin(), cells.end(), occupied.begin(),
                 [](SliceCell c) { return static_cast<std::uint8_t>(c == SliceCell::kOccupied); });
  // The cap in whole cells, at most the grid's extent (beyond it nothing changes).
  const double r = grid.resolution();
  const int cap_cells = static_cast<int>(
      std::min(std::ceil(max_distance_m / r), static_cast<double>(grid.sizeX() + grid.sizeY())));
  const CellBounds all{0, 0, grid.sizeX() - 1, grid.sizeY() - 1};
  std::vector<std::int32_t> squared;
  boundedSquaredDistances(occupied.data(), grid.sizeX(), all, all, cap_cells, &squared);
  const float cap = static_cast<float>(max_distance_m);
  for (std::size_t i = 0; i < n; ++i) {
    if (cells[i] == SliceCell::kUnknown) continue;
    distance[i] = squared[i] == kFarSquared
                      ? cap
                      : std::min(cap, static_cast<float>(std::sqrt(double(squared[i])) * r));
  }
  return distance;
}

}  // namespace downstream_perception
