#include "downstream_perception/core/tsdf/esdf_band.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "downstream_perception/core/tsdf/distance_transform_3d.h"
#include "downstream_perception/core/tsdf/esdf.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"

namespace downstream_perception {

namespace {
// The transform's squared radius must stay below kEdtFarSquared in int32. A cap beyond this many
// voxels (the nodelet's largest, 100 m, at voxels under 3.1 mm) reads the cap from here on.
constexpr int kMaxRadiusVoxels = 32000;

/// One cell per voxel column, cell centres on voxel centres (1e-6 of a voxel of rounding).
bool onLattice(const GridGeometry& grid, double s) {
  const auto whole = [](double v) { return std::abs(v - std::round(v)) < 1e-6; };
  return std::abs(grid.resolution() - s) <= 1e-9 * s && whole(grid.originX() / s + 0.5) &&
         whole(grid.originY() / s + 0.5);
}
}  // namespace

std::string EsdfBandConfig::validate(double voxel_size_m) const {
  std::ostringstream why;
  if (!(std::isfinite(min_z_m) && std::isfinite(max_z_m) && min_z_m < max_z_m)) {
    why << "need finite min_z_m < max_z_m, got " << min_z_m << " and " << max_z_m;
  } else if (!(std::isfinite(max_distance_m) && max_distance_m >= voxel_size_m &&
               max_distance_m <= kMaxDistanceM)) {
    why << "max_distance_m must be in [" << voxel_size_m << " (one voxel), " << kMaxDistanceM
        << "] m, got " << max_distance_m;
  } else if (grid && grid->cellCount() > 0 && !onLattice(*grid, voxel_size_m)) {
    why << "the grid must have one cell per voxel column (resolution " << voxel_size_m
        << " m, origin half a voxel below a voxel centre), got resolution " << grid->resolution()
        << " m, origin " << grid->originX() << ", " << grid->originY();
  }
  return why.str();
}

namespace {

/// The voxel columns under a grid on the lattice (cell (0, 0) holds column (min_x, min_y)).
ColumnBox gridColumns(const GridGeometry& grid, double s) {
  ColumnBox box;
  if (grid.cellCount() == 0) return box;
  box.min_x = std::llround(grid.originX() / s + 0.5);
  box.min_y = std::llround(grid.originY() / s + 0.5);
  box.max_x = box.min_x + grid.sizeX() - 1;
  box.max_y = box.min_y + grid.sizeY() - 1;
  return box;
}

/// Column labels over `box` (row-major, x fastest), the ESDF's states: occupied wins over free,
/// free over unknown (the enum's order). Counts the known band voxels over `counted`.
std::vector<std::uint8_t> bandLabels(const TsdfMap& map, const EsdfBandConfig& config,
                                     const ColumnBox& box, const ColumnBox& counted,
                                     std::size_t* voxels_counted) {
  const std::int64_t nx = box.width();
  std::vector<std::uint8_t> labels(static_cast<std::size_t>(nx * box.height()),
                                   static_cast<std::uint8_t>(EsdfState::kUnknown));
  const VoxelLayers layers = bandLayers(config.min_z_m, config.max_z_m, map.voxelSize());
  const float min_weight = static_cast<float>(map.config().min_weight);
  for (const auto& [key, block] : map.blocks()) {
    const int z0 = key.z() * kTsdfBlockSide;
    if (z0 + kTsdfBlockSide - 1 < layers.first || z0 > layers.last) continue;
    const std::int64_t bx = std::int64_t{key.x()} * kTsdfBlockSide;
    const std::int64_t by = std::int64_t{key.y()} * kTsdfBlockSide;
    // The block's columns inside the box (a window over a wide map skips most blocks here).
    const ColumnBox in =
        box.intersected({bx, by, bx + kTsdfBlockSide - 1, by + kTsdfBlockSide - 1});
    if (in.empty()) continue;
    for (int z = std::max(0, layers.first - z0); z < kTsdfBlockSide && z0 + z <= layers.last; ++z) {
      for (std::int64_t j = in.min_y; j <= in.max_y; ++j) {
        const std::int64_t row = (j - box.min_y) * nx - box.min_x;
        const bool row_counted = j >= counted.min_y && j <= counted.max_y;
        for (std::int64_t i = in.min_x; i <= in.max_x; ++i) {
          const TsdfVoxel& v = block->voxels[TsdfBlock::linear(static_cast<int>(i - bx),
                                                               static_cast<int>(j - by), z)];
          const EsdfState st = esdfStateOf(v, min_weight);
          *voxels_counted +=
              st != EsdfState::kUnknown && row_counted && i >= counted.min_x && i <= counted.max_x;
          std::uint8_t& label = labels[static_cast<std::size_t>(row + i)];
          label = std::max(label, static_cast<std::uint8_t>(st));
        }
      }
    }
  }
  return labels;
}

}  // namespace

EsdfBandSlice esdfBandSlice(const TsdfMap& map, const EsdfBandConfig& config) {
  const std::string why = config.validate(map.voxelSize());
  if (!why.empty()) throw std::invalid_argument("esdf band: " + why);
  EsdfBandSlice out;
  out.grid = config.grid ? *config.grid : sliceGeometry(map);
  const int nx = out.grid.sizeX();
  const int ny = out.grid.sizeY();
  const std::size_t n = out.grid.cellCount();
  out.distance_m.assign(n, std::numeric_limits<float>::quiet_NaN());
  if (n == 0) return out;

  // The transform runs over the grid grown by the cap's reach: an obstacle outside the grid
  // but within max_distance_m of a cell inside still sets that cell's value, which therefore
  // equals the whole map's. Beyond the blocks there are no seeds, so the growth stops there.
  const double s = map.voxelSize();
  const double radius = std::ceil(config.max_distance_m / s + 0.5);
  std::int64_t reach = static_cast<std::int64_t>(std::min(radius, double{kMaxRadiusVoxels}));
  const auto fits = [&](std::int64_t r) {
    return (static_cast<double>(nx) + 2.0 * r) * (static_cast<double>(ny) + 2.0 * r) <=
           static_cast<double>(config.max_computed_columns);
  };
  if (config.max_computed_columns > 0 && !fits(reach)) {
    // The widest padding that fits (none if the grid alone fills the bound).
    std::int64_t lo = 0;
    std::int64_t hi = reach;
    while (lo < hi) {
      const std::int64_t mid = (lo + hi + 1) / 2;
      if (fits(mid)) {
        lo = mid;
      } else {
        hi = mid - 1;
      }
    }
    reach = lo;
    out.stats.padding_cut = true;
  }
  out.stats.padding_voxels = static_cast<std::size_t>(reach);
  const ColumnBox target = gridColumns(out.grid, s);
  const ColumnBox box = target.grown(reach).intersected(blockColumns(map).hull(target));
  const int px = static_cast<int>(box.width());
  const int py = static_cast<int>(box.height());
  out.stats.columns_computed = static_cast<std::size_t>(px) * py;
  const std::vector<std::uint8_t> labels =
      bandLabels(map, config, box, target, &out.stats.voxels_in_band);
  // Cell (x, y) of the grid is column (x + dx, y + dy) of the computed box.
  const std::int64_t dx = target.min_x - box.min_x;
  const std::int64_t dy = target.min_y - box.min_y;
  const auto inner = [&](int x, int y) { return static_cast<std::size_t>((y + dy) * px + x + dx); };
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const std::uint8_t l = labels[inner(x, y)];
      out.stats.columns_occupied += l == static_cast<std::uint8_t>(EsdfState::kOccupied);
      out.stats.columns_free += l == static_cast<std::uint8_t>(EsdfState::kFree);
    }
  }

  // As the ESDF: free columns take the distance to the nearest occupied one, occupied columns
  // (negative) to the nearest free one; one layer, so the transform is the 2-D one.
  const int radius_voxels = static_cast<int>(
      std::min({radius, static_cast<double>(px) + py + 1, double{kMaxRadiusVoxels}}));
  std::vector<std::int32_t> squared;
  EdtScratch scratch;
  for (const EsdfState target_state : {EsdfState::kFree, EsdfState::kOccupied}) {
    const bool occupied = target_state == EsdfState::kOccupied;
    const std::size_t targets = occupied ? out.stats.columns_occupied : out.stats.columns_free;
    if (targets == 0) continue;
    const auto seed = static_cast<std::uint8_t>(occupied ? EsdfState::kFree : EsdfState::kOccupied);
    boundedSquaredDistances3d(labels.data(), Eigen::Vector3i(px, py, 1), seed, radius_voxels,
                              &squared, &scratch);
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        const std::size_t k = inner(x, y);
        if (labels[k] == static_cast<std::uint8_t>(target_state)) {
          out.distance_m[out.grid.index(x, y)] =
              esdfMetres(squared[k], occupied, s, config.max_distance_m);
        }
      }
    }
  }
  return out;
}

}  // namespace downstream_perception
