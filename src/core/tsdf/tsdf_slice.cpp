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

GridGeometry sliceGeometry(const TsdfMap& map) {
  if (map.blockCount() == 0) return GridGeometry();
  Eigen::Vector2i lo = Eigen::Vector2i::Constant(std::numeric_limits<int>::max());
  Eigen::Vector2i hi = Eigen::Vector2i::Constant(std::numeric_limits<int>::min());
  for (const auto& kv : map.blocks()) {
    lo = lo.cwiseMin(kv.first.head<2>());
    hi = hi.cwiseMax(kv.first.head<2>());
  }
  const double s = map.voxelSize();
  return GridGeometry((hi.x() - lo.x() + 1) * kTsdfBlockSide,
                      (hi.y() - lo.y() + 1) * kTsdfBlockSide, s,
                      (lo.x() * kTsdfBlockSide - 0.5) * s, (lo.y() * kTsdfBlockSide - 0.5) * s);
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
  for (const auto& [key, block] : map.blocks()) {
    const int z0 = key.z() * kTsdfBlockSide;
    if (z0 + kTsdfBlockSide - 1 < k_min || z0 > k_max) continue;
    for (int z = std::max(0, k_min - z0); z < kTsdfBlockSide && z0 + z <= k_max; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const TsdfVoxel& v = block->voxels[TsdfBlock::linear(x, y, z)];
          if (!(v.weight > min_weight)) continue;
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
