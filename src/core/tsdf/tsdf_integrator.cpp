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
/// drop-off applied to sdf (m). The settings are read once per frame, not once per voxel.
class ObservationWeight {
 public:
  ObservationWeight(const TsdfConfig& c, float mu)
      : inverse_square_(c.weighting == TsdfConfig::Weighting::kInverseSquareDepth),
        dropoff_(c.behind_surface_dropoff),
        s_(static_cast<float>(c.voxel_size_m)),
        mu_(mu) {}
  float operator()(float z, float sdf) const {
    float w = inverse_square_ ? 1.0f / (z * z) : 1.0f;
    if (dropoff_ && sdf < -s_) w *= (mu_ + sdf) / (mu_ - s_);
    return w;
  }

 private:
  bool inverse_square_;
  bool dropoff_;
  float s_;
  float mu_;
};

Eigen::Vector3i blockOfPoint(const Eigen::Vector3d& p, double inv_voxel) {
  // Voxel = round(p / s); block = floor(voxel / 8), computed on doubles.
  const Eigen::Vector3d q = p * inv_voxel + Eigen::Vector3d::Constant(0.5);
  // floor(floor(q) / 8) = floor(q / 8), and dividing by 8 is exact in binary floating point.
  constexpr double kInvSide = 1.0 / kTsdfBlockSide;
  return {static_cast<int>(std::floor(q.x() * kInvSide)),
          static_cast<int>(std::floor(q.y() * kInvSide)),
          static_cast<int>(std::floor(q.z() * kInvSide))};
}

// A depth image checked once per frame: depth (m; NaN invalid, +Inf no return) and inverse
// depth (1/m; 0 where not a finite valid depth), so the per-voxel loop does no validation and no
// division for interpolation.
struct DepthFrame {
  std::vector<float> depth;
  std::vector<float> inverse;
  const float* range_per_depth = nullptr;  ///< |(x/z, y/z, 1)| of each pixel's ray
  /// Pixels within edge_guard_rad of a depth edge (a jump of more than mu between neighbours, or
  /// an invalid neighbour): what lies behind them is not known to be behind a surface.
  std::vector<std::uint8_t> near_edge;
  /// 1 where the 2 x 2 pixels from this one (right, down) are all valid depths within a voxel
  /// of each other: inverse depth may be interpolated between them. Checked once per pixel here
  /// instead of once per voxel in the integration loop (empty without interpolate_depth).
  std::vector<std::uint8_t> smooth;
  float min_depth = std::numeric_limits<float>::infinity();
};

DepthFrame prepare(const float* depth, const PinholeCamera& camera, const TsdfConfig& c,
                   TsdfIntegrationStats* stats) {
  DepthFrame f;
  const std::size_t n = static_cast<std::size_t>(camera.width) * camera.height;
  f.depth.resize(n);
  f.inverse.resize(n);
  // |ray| / z per pixel depends on the intrinsics only: computed once per camera (per thread).
  thread_local PinholeCamera cached_camera;
  thread_local std::vector<float> cached_range;
  if (cached_range.size() != n || cached_camera.fx != camera.fx || cached_camera.fy != camera.fy ||
      cached_camera.cx != camera.cx || cached_camera.cy != camera.cy ||
      cached_camera.width != camera.width) {
    cached_range.resize(n);
    for (int v = 0; v < camera.height; ++v) {
      const double y = (v - camera.cy) / camera.fy;
      for (int u = 0; u < camera.width; ++u) {
        const double x = (u - camera.cx) / camera.fx;
        cached_range[static_cast<std::size_t>(v) * camera.width + u] =
            static_cast<float>(std::sqrt(1.0 + x * x + y * y));
      }
    }
    cached_camera = camera;
  }
  f.range_per_depth = cached_range.data();
  for (std::size_t i = 0; i < n; ++i) {
    const float d = depth[i];
    if (std::isinf(d) && d > 0.0f) {
      ++stats->pixels_no_return;
      f.depth[i] = d;
      f.inverse[i] = 0.0f;
    } else if (d >= c.min_depth_m && d <= c.max_depth_m) {
      ++stats->pixels_valid;
      f.depth[i] = d;
      f.inverse[i] = 1.0f / d;
      f.min_depth = std::min(f.min_depth, d);
    } else {
      ++stats->pixels_invalid;
      f.depth[i] = std::numeric_limits<float>::quiet_NaN();
      f.inverse[i] = 0.0f;
    }
  }
  if (c.interpolate_depth) {
    const int w = camera.width, h = camera.height;
    const float max_step = static_cast<float>(c.voxel_size_m);
    f.smooth.assign(n, 0);
    for (int v = 0; v + 1 < h; ++v) {
      for (int u = 0; u + 1 < w; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        const float* inv = f.inverse.data() + i;
        const float* d = f.depth.data() + i;
        const float lo = std::min(std::min(d[0], d[1]), std::min(d[w], d[w + 1]));
        const float hi = std::max(std::max(d[0], d[1]), std::max(d[w], d[w + 1]));
        f.smooth[i] = (inv[0] != 0.0f) & (inv[1] != 0.0f) & (inv[w] != 0.0f) &
                      (inv[w + 1] != 0.0f) & (hi - lo <= max_step);
      }
    }
  }
  const int radius =
      static_cast<int>(std::ceil(c.edge_guard_rad * std::max(camera.fx, camera.fy) - 1e-9));
  if (radius > 0) {
    const int w = camera.width, h = camera.height;
    std::vector<std::uint8_t> edge(n, 0);
    const float jump = static_cast<float>(c.truncation());
    const float* inv = f.inverse.data();
    const float* dep = f.depth.data();
    // A neighbour differs when it is invalid (NaN, +Inf: the compare below is false for both)
    // or more than mu away in depth.
    const auto differs = [&](std::size_t j, float d) { return !(std::abs(dep[j] - d) <= jump); };
    for (int v = 0; v < h; ++v) {
      const bool inner_row = v > 0 && v + 1 < h;
      if (inner_row && w > 2) {
        // Inside the image no bounds to check: branch-free, so the compiler vectorises it.
        for (int u = 1; u + 1 < w; ++u) {
          const std::size_t i = static_cast<std::size_t>(v) * w + u;
          const float d = dep[i];
          edge[i] = (inv[i] != 0.0f) &
                    (differs(i + 1, d) | differs(i - 1, d) | differs(i + w, d) | differs(i - w, d));
        }
      }
      for (int u = 0; u < w; ++u) {
        if (inner_row && u > 0 && u + 1 < w) continue;  // done above
        const std::size_t i = static_cast<std::size_t>(v) * w + u;
        if (inv[i] == 0.0f) continue;
        const float d = dep[i];
        edge[i] = (u + 1 < w && differs(i + 1, d)) || (u > 0 && differs(i - 1, d)) ||
                  (v + 1 < h && differs(i + w, d)) || (v > 0 && differs(i - w, d));
      }
    }
    // Dilate by `radius` (separable box: rows, then columns), as ORs of shifted copies: each
    // pass is a plain byte loop the compiler vectorises.
    std::vector<std::uint8_t> rows(n, 0);
    for (int k = -radius; k <= radius; ++k) {
      const int u0 = std::max(0, -k), u1 = std::min(w, w - k);
      for (int v = 0; v < h; ++v) {
        const std::uint8_t* src = edge.data() + static_cast<std::size_t>(v) * w + k;
        std::uint8_t* dst = rows.data() + static_cast<std::size_t>(v) * w;
        for (int u = u0; u < u1; ++u) dst[u] |= src[u];
      }
    }
    f.near_edge.assign(n, 0);
    for (int k = -radius; k <= radius; ++k) {
      const int v0 = std::max(0, -k), v1 = std::min(h, h - k);
      for (int v = v0; v < v1; ++v) {
        const std::uint8_t* src = rows.data() + static_cast<std::size_t>(v + k) * w;
        std::uint8_t* dst = f.near_edge.data() + static_cast<std::size_t>(v) * w;
        for (int u = 0; u < w; ++u) dst[u] |= src[u];
      }
    }
  }
  return f;
}

/// Depth at a sub-pixel position: inverse depth interpolated bilinearly between the four
/// surrounding pixel centres (exact on planes, where 1/z is affine in the image), or `nearest`
/// when a neighbour is not a valid depth or the four differ by more than the voxel size (a depth
/// edge: interpolating there would put surface in free space; DepthFrame::smooth).
float interpolatedDepth(const DepthFrame& f, int w, float uf, float vf, float nearest) {
  if (uf < 0.0f || vf < 0.0f) return nearest;
  const int u0 = static_cast<int>(uf);
  const int v0 = static_cast<int>(vf);
  const std::size_t i = static_cast<std::size_t>(v0) * w + u0;
  if (!f.smooth[i]) return nearest;  // also 0 in the last row and column
  const float* inv = f.inverse.data() + i;
  const float a = uf - static_cast<float>(u0), b = vf - static_cast<float>(v0);
  return 1.0f / ((1.0f - b) * ((1.0f - a) * inv[0] + a * inv[1]) +
                 b * ((1.0f - a) * inv[w] + a * inv[w + 1]));
}

/// Blocks the truncation band of the valid pixels passes through. Pixels are sampled every
/// `stride` pixels, where a stride spans at most one voxel at the nearest depth of the frame
/// (so no surface patch a voxel wide is skipped); neighbouring samples mostly land in the same
/// block, so a one-entry cache per sample along the ray skips most hash lookups.
tsl::robin_set<Eigen::Vector3i, BlockIndexHash> bandBlocks(const DepthFrame& f,
                                                           const PinholeCamera& camera,
                                                           const Eigen::Isometry3d& T,
                                                           const TsdfConfig& c) {
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> keys;
  if (!std::isfinite(f.min_depth)) return keys;
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const double block_m = kTsdfBlockSide * s;
  const int stride = std::max(
      1, static_cast<int>(std::floor(0.5 * s * std::min(camera.fx, camera.fy) / f.min_depth)));
  const int samples = std::max(2, static_cast<int>(std::ceil(2.0 * mu / (0.5 * block_m))) + 1);
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  const int w = camera.width, h = camera.height;
  // One cache per sample along the ray: neighbouring pixels' k-th samples share blocks.
  std::vector<Eigen::Vector3i> last(samples,
                                    Eigen::Vector3i(std::numeric_limits<int>::min(), 0, 0));
  const auto next = [stride](int a, int size) {
    // Every stride-th pixel and always the last one.
    return a + stride < size || a == size - 1 ? a + stride : size - 1;
  };
  for (int v = 0; v < h; v = next(v, h)) {
    for (int u = 0; u < w; u = next(u, w)) {
      const float d = f.depth[static_cast<std::size_t>(v) * w + u];
      if (!std::isfinite(d)) continue;
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double norm = ray.norm();
      const double range = d * norm;
      const Eigen::Vector3d dir = R * (ray / norm);
      const double r0 = std::max(0.0, range - mu);
      const double step = (range + mu - r0) / (samples - 1);
      for (int k = 0; k < samples; ++k) {
        const Eigen::Vector3i key = blockOfPoint(t + dir * (r0 + step * k), 1.0 / s);
        if (key == last[k]) continue;
        last[k] = key;
        keys.insert(key);
      }
    }
  }
  return keys;
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
  const double mu = c.truncation();
  const int w = camera.width;
  const int h = camera.height;
  const std::uint64_t generation = map->beginIntegration();
  const DepthFrame frame = prepare(depth, camera, c, &stats);
  const auto keys = bandBlocks(frame, camera, T_map_camera, c);

  // Every voxel of those blocks: project to the nearest pixel centre, fuse.
  const float max_step = static_cast<float>(s);
  const Eigen::Isometry3d T_camera_map = T_map_camera.inverse();
  // The voxel loop runs in float (voxel positions relative to the camera, within max_depth_m:
  // float resolves them to well under a micrometre per metre).
  const Eigen::Matrix3f Rc = T_camera_map.linear().cast<float>();
  const Eigen::Vector3f dx = Rc.col(0) * static_cast<float>(s);
  const Eigen::Vector3f dy = Rc.col(1) * static_cast<float>(s);
  const Eigen::Vector3f dz = Rc.col(2) * static_cast<float>(s);
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx) + 0.5f, cy = static_cast<float>(camera.cy) + 0.5f;
  const float min_z = static_cast<float>(c.min_depth_m), max_z = static_cast<float>(c.max_depth_m);
  const float muf = static_cast<float>(mu), sf = static_cast<float>(s);
  const float u_end = static_cast<float>(w), v_end = static_cast<float>(h);
  const bool interpolate = c.interpolate_depth;
  const ObservationWeight weight(c, muf);
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
    const Eigen::Vector3f base =
        (T_camera_map * ((key * kTsdfBlockSide).cast<double>() * s)).cast<float>();
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        Eigen::Vector3f p = base + dz * static_cast<float>(z) + dy * static_cast<float>(y);
        TsdfVoxel* voxel = &block->voxels[TsdfBlock::linear(0, y, z)];
        for (int x = 0; x < kTsdfBlockSide; ++x, p += dx, ++voxel) {
          const float zc = p.z();
          if (zc < min_z) continue;
          const float inv_z = 1.0f / zc;
          // Shifted by half a pixel, so truncation below is rounding to the nearest pixel
          // centre (no half-pixel bias).
          const float us = fx * p.x() * inv_z + cx;
          const float vs = fy * p.y() * inv_z + cy;
          if (!(us >= 0.0f && vs >= 0.0f && us < u_end && vs < v_end)) continue;
          // Through int: a float to unsigned 64-bit conversion has no single x86 instruction.
          const std::size_t pixel =
              static_cast<std::size_t>(static_cast<int>(vs) * w + static_cast<int>(us));
          const float nearest = frame.depth[pixel];
          float sdf;
          if (nearest > max_z) {  // +Inf: no return within range, free along the whole ray
            if (zc > max_z) continue;
            sdf = muf;
          } else if (nearest == nearest) {
            // sdf = (depth - z) * |ray| / z, with |ray| / z from the pixel's table. Interpolation
            // moves the depth by at most max_step, so voxels clearly outside the band skip it.
            const float along_axis = nearest - zc;
            if (along_axis < -muf - max_step) continue;
            if (along_axis > muf + max_step) {
              sdf = muf;
            } else {
              const float d = interpolate
                                  ? interpolatedDepth(frame, w, us - 0.5f, vs - 0.5f, nearest)
                                  : nearest;
              sdf = (d - zc) * frame.range_per_depth[pixel];
              if (sdf < -muf) continue;
              // Behind a depth edge the ray grazed an object's rim: no evidence of "inside".
              if (sdf < -sf && !frame.near_edge.empty() && frame.near_edge[pixel]) continue;
            }
          } else {
            continue;  // NaN: invalid pixel
          }
          const float dn = std::min(1.0f, sdf / muf);
          map->fuse(voxel, dn, weight(nearest > max_z ? zc : nearest, sdf));
          ++stats.voxels_updated;
          touched = true;
        }
      }
    }
    if (touched) block->updated_stamp = generation;
  }
  evict(map, T_map_camera.translation(), &stats);
  return stats;
}

void millimetresToMetres(const std::uint16_t* millimetres, std::size_t count, float* metres) {
  for (std::size_t i = 0; i < count; ++i) {
    metres[i] = millimetres[i] == 0 ? std::numeric_limits<float>::quiet_NaN()
                                    : 0.001f * static_cast<float>(millimetres[i]);
  }
}

TsdfIntegrationStats integratePoints(TsdfMap* map, const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& origin) {
  TsdfIntegrationStats stats;
  const TsdfConfig& c = map->config();
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const ObservationWeight weight(c, static_cast<float>(mu));
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
                    weight(static_cast<float>(range), static_cast<float>(sdf)));
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
