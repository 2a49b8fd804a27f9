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
}  // namespace

std::string EsdfBandConfig::validate(double voxel_size_m) const {
  std::ostringstream why;
  if (!(std::isfinite(min_z_m) && std::isfinite(max_z_m) && min_z_m < max_z_m)) {
    why << "need finite min_z_m < max_z_m, got " << min_z_m << " and " << max_z_m;
  } else if (!(std::isfinite(max_distance_m) && max_distance_m >= voxel_size_m &&
               max_distance_m <= kMaxDistanceM)) {
    why << "max_distance_m must be in [" << voxel_size_m << " (one voxel), " << kMaxDistanceM
        << "] m, got " << max_distance_m;
  }
  return why.str();
}

EsdfBandSlice esdfBandSlice(const TsdfMap& map, const EsdfBandConfig& config) {
  const std::string why = config.validate(map.voxelSize());
  if (!why.empty()) throw std::invalid_argument("esdf band: " + why);
  EsdfBandSlice out;
  out.grid = sliceGeometry(map);
  const int nx = out.grid.sizeX();
  const int ny = out.grid.sizeY();
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  out.distance_m.assign(n, std::numeric_limits<float>::quiet_NaN());
  if (n == 0) return out;

  // Column states, the ESDF's labels: occupied wins over free, free over unknown (the enum's
  // order). sliceGeometry puts voxel column (i, j) in cell (i - x0, j - y0).
  std::vector<std::uint8_t> labels(n, static_cast<std::uint8_t>(EsdfState::kUnknown));
  const double s = map.voxelSize();
  const int x0 = static_cast<int>(std::lround(out.grid.originX() / s + 0.5));
  const int y0 = static_cast<int>(std::lround(out.grid.originY() / s + 0.5));
  const VoxelLayers layers = bandLayers(config.min_z_m, config.max_z_m, s);
  const float min_weight = static_cast<float>(map.config().min_weight);
  for (const auto& [key, block] : map.blocks()) {
    const int z0 = key.z() * kTsdfBlockSide;
    if (z0 + kTsdfBlockSide - 1 < layers.first || z0 > layers.last) continue;
    const int cx0 = key.x() * kTsdfBlockSide - x0;
    const int cy0 = key.y() * kTsdfBlockSide - y0;
    for (int z = std::max(0, layers.first - z0); z < kTsdfBlockSide && z0 + z <= layers.last; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        std::uint8_t* row = labels.data() + static_cast<std::size_t>(cy0 + y) * nx + cx0;
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const EsdfState st = esdfStateOf(block->voxels[TsdfBlock::linear(x, y, z)], min_weight);
          out.stats.voxels_in_band += st != EsdfState::kUnknown;
          row[x] = std::max(row[x], static_cast<std::uint8_t>(st));
        }
      }
    }
  }
  for (const std::uint8_t l : labels) {
    out.stats.columns_occupied += l == static_cast<std::uint8_t>(EsdfState::kOccupied);
    out.stats.columns_free += l == static_cast<std::uint8_t>(EsdfState::kFree);
  }

  // As the ESDF: free columns take the distance to the nearest occupied one, occupied columns
  // (negative) to the nearest free one; one layer, so the transform is the 2-D one.
  const double radius = std::ceil(config.max_distance_m / s + 0.5);
  const int radius_voxels = static_cast<int>(
      std::min({radius, static_cast<double>(nx) + ny + 1, double{kMaxRadiusVoxels}}));
  std::vector<std::int32_t> squared, scratch;
  for (const EsdfState target : {EsdfState::kFree, EsdfState::kOccupied}) {
    const bool occupied = target == EsdfState::kOccupied;
    const std::size_t targets = occupied ? out.stats.columns_occupied : out.stats.columns_free;
    if (targets == 0) continue;
    const auto seed = static_cast<std::uint8_t>(occupied ? EsdfState::kFree : EsdfState::kOccupied);
    boundedSquaredDistances3d(labels.data(), Eigen::Vector3i(nx, ny, 1), seed, radius_voxels,
                              &squared, &scratch);
    for (std::size_t i = 0; i < n; ++i) {
      if (labels[i] == static_cast<std::uint8_t>(target)) {
        out.distance_m[i] = esdfMetres(squared[i], occupied, s, config.max_distance_m);
      }
    }
  }
  return out;
}

}  // namespace downstream_perception
