#include "downstream_perception/core/tsdf/tsdf_integrator.h"

#include <tsl/robin_set.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace downstream_perception {

std::string PinholeCamera::validate() const {
  std::ostringstream why;
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0.0 && fy > 0.0)) {
    why << "focal lengths must be finite and > 0, got fx " << fx << ", fy " << fy;
  } else if (!(std::isfinite(cx) && std::isfinite(cy))) {
    why << "principal point must be finite";
  } else if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    why << "image size must be in [1, 16384] pixels, got " << width << " x " << height;
  }
  return why.str();
}

namespace {

/// Observation weight of a depth z (m) for the configured weighting, with the behind-surface
/// drop-off applied to sdf (m).
float observationWeight(const TsdfConfig& c, double z, double sdf, double mu) {
  double w = c.weighting == TsdfConfig::Weighting::kInverseSquareDepth ? 1.0 / (z * z) : 1.0;
  const double s = c.voxel_size_m;
  if (c.behind_surface_dropoff && sdf < -s) w *= (mu + sdf) / (mu - s);
  return static_cast<float>(w);
}

Eigen::Vector3i blockOfPoint(const Eigen::Vector3d& p, double inv_voxel) {
  // Voxel = round(p / s); block = floor(voxel / 8), computed on doubles.
  const Eigen::Vector3d q = p * inv_voxel + Eigen::Vector3d::Constant(0.5);
  return {static_cast<int>(std::floor(std::floor(q.x()) / kTsdfBlockSide)),
          static_cast<int>(std::floor(std::floor(q.y()) / kTsdfBlockSide)),
          static_cast<int>(std::floor(std::floor(q.z()) / kTsdfBlockSide))};
}

/// Depth at a sub-pixel position: inverse depth interpolated bilinearly between the four
/// surrounding pixel centres (exact on planes, where 1/z is affine in the image), or `nearest`
/// when a neighbour is invalid or the four differ by more than `max_step` (a depth edge:
/// interpolating there would put surface in free space).
float interpolatedDepth(const float* depth, int w, int h, double uf, double vf, float nearest,
                        float max_step) {
  const int u0 = static_cast<int>(std::floor(uf));
  const int v0 = static_cast<int>(std::floor(vf));
  if (u0 < 0 || v0 < 0 || u0 + 1 >= w || v0 + 1 >= h) return nearest;
  const float* row0 = depth + static_cast<std::size_t>(v0) * w + u0;
  const float* row1 = row0 + w;
  const float d00 = row0[0], d10 = row0[1], d01 = row1[0], d11 = row1[1];
  const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
  const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
  // NaN fails both comparisons; +Inf fails the step test.
  if (!(lo > 0.0f) || !(hi - lo <= max_step)) return nearest;
  const float a = static_cast<float>(uf - u0), b = static_cast<float>(vf - v0);
  const float inv = (1.0f - b) * ((1.0f - a) / d00 + a / d10) + b * ((1.0f - a) / d01 + a / d11);
  return 1.0f / inv;
}

void evict(TsdfMap* map, const Eigen::Vector3d& origin, TsdfIntegrationStats* stats) {
  const double limit = map->config().max_block_distance_m;
  if (limit > 0.0) stats->blocks_evicted = map->evictFartherThan(origin, limit);
}

}  // namespace

TsdfIntegrationStats integrateDepth(TsdfMap* map, const float* depth, const PinholeCamera& camera,
                                    const Eigen::Isometry3d& T_map_camera) {
  TsdfIntegrationStats stats;
  const TsdfConfig& c = map->config();
  const double s = c.voxel_size_m;
  const double inv_s = 1.0 / s;
  const double mu = c.truncation();
  const double block_m = kTsdfBlockSide * s;
  const int w = camera.width;
  const int h = camera.height;
  const std::uint64_t generation = map->beginIntegration();

  // 1. Blocks the truncation band of every valid pixel passes through. Neighbouring pixels
  //    mostly land in the same block, so a one-entry cache skips most hash lookups.
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> keys;
  const Eigen::Matrix3d R = T_map_camera.linear();
  const Eigen::Vector3d t = T_map_camera.translation();
  const int samples = std::max(2, static_cast<int>(std::ceil(2.0 * mu / (0.5 * block_m))) + 1);
  Eigen::Vector3i last(std::numeric_limits<int>::min(), 0, 0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float d = depth[static_cast<std::size_t>(v) * w + u];
      if (std::isinf(d) && d > 0.0f) {
        ++stats.pixels_no_return;
        continue;
      }
      if (!(d >= c.min_depth_m && d <= c.max_depth_m)) {
        ++stats.pixels_invalid;
        continue;
      }
      ++stats.pixels_valid;
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double range = d * ray.norm();
      const Eigen::Vector3d dir = R * (ray / ray.norm());
      const double r0 = std::max(0.0, range - mu);
      const double step = (range + mu - r0) / (samples - 1);
      for (int k = 0; k < samples; ++k) {
        const Eigen::Vector3i key = blockOfPoint(t + dir * (r0 + step * k), inv_s);
        if (key == last) continue;
        last = key;
        keys.insert(key);
      }
    }
  }

  // 2. Every voxel of those blocks: project to the nearest pixel centre, fuse.
  const float max_step = static_cast<float>(c.voxel_size_m);
  const Eigen::Isometry3d T_camera_map = T_map_camera.inverse();
  const Eigen::Matrix3d Rc = T_camera_map.linear();
  const Eigen::Vector3d dx = Rc.col(0) * s, dy = Rc.col(1) * s, dz = Rc.col(2) * s;
  for (const Eigen::Vector3i& key : keys) {
    const bool existed = map->find(key) != nullptr;
    TsdfBlock* block = map->allocate(key);
    if (block == nullptr) {
      ++stats.blocks_refused;
      continue;
    }
    stats.blocks_allocated += !existed;
    ++stats.blocks_touched;
    bool touched = false;
    const Eigen::Vector3d base = T_camera_map * ((key * kTsdfBlockSide).cast<double>() * s);
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        Eigen::Vector3d p = base + dz * z + dy * y;
        TsdfVoxel* voxel = &block->voxels[TsdfBlock::linear(0, y, z)];
        for (int x = 0; x < kTsdfBlockSide; ++x, p += dx, ++voxel) {
          const double zc = p.z();
          if (zc < c.min_depth_m) continue;
          const double uf = camera.fx * p.x() / zc + camera.cx;
          const double vf = camera.fy * p.y() / zc + camera.cy;
          const long ui = std::lround(uf);
          const long vi = std::lround(vf);
          if (ui < 0 || vi < 0 || ui >= w || vi >= h) continue;
          float d = depth[static_cast<std::size_t>(vi) * w + ui];
          if (c.interpolate_depth) d = interpolatedDepth(depth, w, h, uf, vf, d, max_step);
          double sdf;
          if (std::isinf(d) && d > 0.0f) {
            if (zc > c.max_depth_m) continue;
            sdf = mu;  // no return within range: free along the whole ray
          } else if (d >= c.min_depth_m && d <= c.max_depth_m) {
            sdf = (d - zc) * (p.norm() / zc);
            if (sdf < -mu) continue;
          } else {
            continue;
          }
          const float dn = static_cast<float>(std::min(1.0, sdf / mu));
          map->fuse(voxel, dn, observationWeight(c, std::isinf(d) ? zc : d, sdf, mu));
          ++stats.voxels_updated;
          touched = true;
        }
      }
    }
    if (touched) block->updated_stamp = generation;
  }
  evict(map, t, &stats);
  return stats;
}

TsdfIntegrationStats integratePoints(TsdfMap* map, const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& origin) {
  TsdfIntegrationStats stats;
  const TsdfConfig& c = map->config();
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const std::uint64_t generation = map->beginIntegration();
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> touched_keys;
  Eigen::Vector3i cached_key(std::numeric_limits<int>::min(), 0, 0);
  TsdfBlock* cached = nullptr;
  for (const Eigen::Vector3d& point : points) {
    if (!point.allFinite()) {
      ++stats.pixels_invalid;
      continue;
    }
    const Eigen::Vector3d ray = point - origin;
    const double range = ray.norm();
    if (!(range >= c.min_depth_m && range <= c.max_depth_m)) {
      ++stats.pixels_invalid;
      continue;
    }
    ++stats.pixels_valid;
    const Eigen::Vector3d dir = ray / range;
    // Amanatides-Woo traversal of the voxels (cells [i - 1/2, i + 1/2) in voxel units) from
    // range - mu to range + mu.
    const double t0 = std::max(0.0, range - mu);
    const double t1 = range + mu;
    const Eigen::Vector3d q0 = (origin + dir * t0) / s + Eigen::Vector3d::Constant(0.5);
    Eigen::Vector3i cell(static_cast<int>(std::floor(q0.x())), static_cast<int>(std::floor(q0.y())),
                         static_cast<int>(std::floor(q0.z())));
    Eigen::Vector3i step;
    Eigen::Vector3d t_max, t_delta;
    for (int a = 0; a < 3; ++a) {
      const double da = dir(a) / s;  // voxel units per metre
      if (da > 0.0) {
        step(a) = 1;
        t_delta(a) = 1.0 / da;
        t_max(a) = t0 + (cell(a) + 1 - q0(a)) / da;
      } else if (da < 0.0) {
        step(a) = -1;
        t_delta(a) = -1.0 / da;
        t_max(a) = t0 + (q0(a) - cell(a)) / -da;
      } else {
        step(a) = 0;
        t_delta(a) = t_max(a) = std::numeric_limits<double>::infinity();
      }
    }
    for (double t_cell = t0; t_cell <= t1;) {
      const Eigen::Vector3i key = TsdfMap::blockOf(cell);
      if (key != cached_key) {
        const bool existed = map->find(key) != nullptr;
        cached = map->allocate(key);
        cached_key = key;
        if (cached == nullptr) {
          ++stats.blocks_refused;
        } else {
          stats.blocks_allocated += !existed;
          touched_keys.insert(key);
          cached->updated_stamp = generation;
        }
      }
      if (cached != nullptr) {
        const double sdf = range - (map->voxelCenter(cell) - origin).dot(dir);
        if (sdf >= -mu) {
          const float dn = static_cast<float>(std::min(1.0, sdf / mu));
          map->fuse(&cached->voxels[TsdfMap::localIndex(cell)], dn,
                    observationWeight(c, range, sdf, mu));
          ++stats.voxels_updated;
        }
      }
      int a = 0;
      if (t_max(1) < t_max(a)) a = 1;
      if (t_max(2) < t_max(a)) a = 2;
      t_cell = t_max(a);
      t_max(a) += t_delta(a);
      cell(a) += step(a);
    }
  }
  stats.blocks_touched = touched_keys.size();
  evict(map, origin, &stats);
  return stats;
}

}  // namespace downstream_perception
