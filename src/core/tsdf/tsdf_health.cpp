#include "downstream_perception/core/tsdf/tsdf_health.h"

#include <cmath>

namespace downstream_perception {

namespace {
/// Half-width of the tie band around D = 0, in voxels: far above float rounding (~1e-4 voxel
/// at 10 m and 2 cm voxels), far below the drift the check is for (more than mu).
constexpr double kSurfaceTieVoxels = 0.01;
}  // namespace

TsdfHealth tsdfHealth(const TsdfMap& map) {
  TsdfHealth health;
  const float min_weight = static_cast<float>(map.config().min_weight);
  const double s = map.voxelSize();
  const double mu = map.config().truncation();
  const int reach = std::max(2, static_cast<int>(std::floor(mu / s)));  // voxels within mu
  // Tie rule: a surface through voxel centres leaves D there at 0 plus rounding of either sign
  // (each view's projective distance rounds its own way), so neighbours along the surface
  // would alternate signs and count as crossings and double crossings. Values within a small
  // fraction of a voxel of 0 count as on the surface, which (as in marching cubes, where
  // D = 0 is outside) is the non-negative side.
  const float tie = static_cast<float>(kSurfaceTieVoxels * s / mu);
  const auto inside = [tie](float d) { return d < -tie; };
  const auto value = [&](const Eigen::Vector3i& v, float* d) {
    const TsdfVoxel* voxel = map.voxel(v);
    if (voxel == nullptr || !(voxel->observedWeight() > min_weight)) return false;
    *d = voxel->distance;
    return true;
  };
  double gradient_sum = 0.0;
  std::size_t low = 0;
  for (const auto& [key, block] : map.blocks()) {
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const TsdfVoxel& here = block->voxels[TsdfBlock::linear(x, y, z)];
          if (!(here.observedWeight() > min_weight)) continue;
          const Eigen::Vector3i v = key * kTsdfBlockSide + Eigen::Vector3i(x, y, z);
          for (int axis = 0; axis < 3; ++axis) {
            Eigen::Vector3i step = Eigen::Vector3i::Zero();
            step(axis) = 1;
            float next = 0.0f;
            if (!value(v + step, &next) || inside(here.distance) == inside(next)) continue;
            ++health.crossings;
            // Gradient at the crossing: central differences around both voxels, in D mu / m.
            Eigen::Vector3d g = Eigen::Vector3d::Zero();
            bool complete = true;
            for (int a = 0; a < 3 && complete; ++a) {
              Eigen::Vector3i e = Eigen::Vector3i::Zero();
              e(a) = 1;
              float lo = 0.0f, hi = 0.0f;
              if (a == axis) {
                g(a) = (next - here.distance) * mu / s;
                continue;
              }
              float lo2 = 0.0f, hi2 = 0.0f;
              complete = value(v - e, &lo) && value(v + e, &hi) && value(v + step - e, &lo2) &&
                         value(v + step + e, &hi2);
              if (complete) g(a) = 0.25 * ((hi - lo) + (hi2 - lo2)) * mu / s;
            }
            // Only crossings along an axis within ~55 degrees of the surface normal count: on a
            // surface through voxel centres, D there is 0 plus per-view rounding of either sign,
            // so neighbours *along* the surface flip sides (issue 22: 38,107 "double crossings"
            // on the clean, lattice-aligned room, more than with pose noise). Every surface has
            // an axis within 54.7 degrees of its normal, and drift's second shell lies along it.
            const double ratio = g.norm();
            if (!complete || !(std::abs(g(axis)) * std::sqrt(3.0) >= ratio)) {
              --health.crossings;
              continue;
            }
            gradient_sum += ratio;
            low += ratio < 0.5;
            // A second crossing back within mu after this one.
            float previous = next;
            for (int k = 2; k <= reach; ++k) {
              float d = 0.0f;
              if (!value(v + step * k, &d)) break;
              if (inside(d) != inside(previous)) {
                ++health.double_crossings;
                break;
              }
              previous = d;
            }
          }
        }
      }
    }
  }
  if (health.crossings > 0) {
    health.mean_gradient_ratio = gradient_sum / static_cast<double>(health.crossings);
    health.low_gradient_fraction = static_cast<double>(low) / static_cast<double>(health.crossings);
  }
  return health;
}

}  // namespace downstream_perception
