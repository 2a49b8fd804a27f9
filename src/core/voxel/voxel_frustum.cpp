// Depth frames with frustum clearing (VoxelMap::integrateDepthFrustum), the spatio-temporal voxel
// layer's way of clearing: instead of walking every pixel's ray through the voxels (a 640 x 480
// frame at 5 cm and 4 m is ~25 M voxel visits), each voxel in view is projected into the image
// once and compared with the depth there (~10^5 voxels). Blocks that lie wholly outside the view
// pyramid or beyond the range are skipped before any voxel is projected.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/voxel/voxel_map.h"

namespace downstream_perception {

namespace {

bool validDepth(float d) {
  return d > 0.0f && d < std::numeric_limits<float>::infinity();
}

bool noReturn(float d, bool zero_is_no_return) {
  return d == std::numeric_limits<float>::infinity() || (d == 0.0f && zero_is_no_return);
}

}  // namespace

VoxelIntegrationStats VoxelMap::integrateDepthFrustum(const float* depth_m,
                                                      const PinholeCamera& camera,
                                                      const Eigen::Isometry3d& T_world_camera,
                                                      bool zero_is_no_return, int stride,
                                                      double stamp_s, const VoxelRayConfig& rays) {
  std::string why = camera.validate();
  if (why.empty() && stride < 1) why = "stride must be >= 1";
  if (why.empty() && depth_m == nullptr) why = "null image";
  if (why.empty() && !T_world_camera.matrix().allFinite()) why = "camera pose is not finite";
  if (why.empty() && !std::isfinite(stamp_s)) why = "stamp is not finite";
  if (why.empty()) why = rays.validate();
  if (!why.empty()) throw std::invalid_argument("voxel map: depth frame: " + why);
  VoxelIntegrationStats stats;
  const float stamp = beginFrame(stamp_s);
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d t = T_world_camera.translation();
  const double res = config_.resolution_m;
  const double zres = config_.z_resolution_m;
  const double ox = windowOriginX();
  const double oy = windowOriginY();
  const double oz = config_.origin_z_m;
  // Pass 1: returns mark their voxel (claiming it for this frame: hits first). Float arithmetic
  // relative to the window origin; a pixel's direction is the row's plus a step per column.
  // Neighbouring pixels mostly fall in the same voxel, so a repeat of the previous one is skipped
  // before any table lookup.
  const Eigen::Matrix3f Rf = R.cast<float>();
  const Eigen::Vector3f t_rel(static_cast<float>(t.x() - ox), static_cast<float>(t.y() - oy),
                              static_cast<float>(t.z() - oz));
  const Eigen::Vector3f scale(static_cast<float>(1.0 / res), static_cast<float>(1.0 / res),
                              static_cast<float>(1.0 / zres));
  const auto mark2 = static_cast<float>(rays.obstacle_max_range_m * rays.obstacle_max_range_m);
  const auto nxf = static_cast<float>(nx_), nyf = static_cast<float>(ny_);
  const auto nzf = static_cast<float>(config_.z_voxels);
  const auto ifx = static_cast<float>(1.0 / camera.fx);
  const auto ify = static_cast<float>(1.0 / camera.fy);
  // Voxels marked recently in this frame, direct-mapped by key: noisy depths make neighbouring
  // pixels alternate between a few voxels, and each repeat would otherwise cost a block lookup
  // only to find the voxel updated already (updateVoxel's frame tag). Exact: a key is skipped
  // only if it was updated in this frame.
  constexpr std::size_t kRecent = 1024;
  std::array<std::int64_t, kRecent> recent;
  recent.fill(-1);
  const auto nx64 = static_cast<std::int64_t>(nx_);
  const auto nxy64 = nx64 * ny_;
  for (int v = 0; v < camera.height; v += stride) {
    const float ry = (static_cast<float>(v) - static_cast<float>(camera.cy)) * ify;
    const Eigen::Vector3f row_dir = Rf.col(1) * ry + Rf.col(2);
    const float* row = depth_m + static_cast<std::size_t>(v) * camera.width;
    for (int u = 0; u < camera.width; u += stride) {
      const float d = row[u];
      if (noReturn(d, zero_is_no_return)) {
        ++stats.rays;
        continue;
      }
      if (!validDepth(d)) {
        ++stats.invalid_points;
        continue;
      }
      ++stats.rays;
      if (!rays.marking) continue;
      const float rx = (static_cast<float>(u) - static_cast<float>(camera.cx)) * ifx;
      if (d * d * (rx * rx + ry * ry + 1.0f) > mark2) continue;
      const Eigen::Vector3f c = (t_rel + (row_dir + Rf.col(0) * rx) * d).cwiseProduct(scale);
      if (!(c.x() >= 0.0f && c.y() >= 0.0f && c.z() >= 0.0f && c.x() < nxf && c.y() < nyf &&
            c.z() < nzf)) {
        continue;
      }
      const int x = static_cast<int>(c.x()), y = static_cast<int>(c.y());
      const int z = static_cast<int>(c.z());
      const std::int64_t key = z * nxy64 + y * nx64 + x;
      std::int64_t& slot = recent[static_cast<std::size_t>(key) & (kRecent - 1)];
      if (slot == key) continue;
      slot = key;
      update(x, y, z, hit_, stamp, &stats);
    }
  }
  if (rays.clearing) {
    clearFrustum(depth_m, camera, T_world_camera, zero_is_no_return, rays, stamp, &stats);
  }
  return stats;
}

void VoxelMap::clearFrustum(const float* depth_m, const PinholeCamera& camera,
                            const Eigen::Isometry3d& T_world_camera, bool zero_is_no_return,
                            const VoxelRayConfig& rays, float stamp, VoxelIntegrationStats* stats) {
  const double range = std::max(rays.raytrace_max_range_m, rays.no_return_range_m);
  if (!(range > 0.0)) return;
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d t = T_world_camera.translation();
  // The view pyramid: apex at the camera, edges through the image's outer pixel edges, cut by the
  // plane z = range (every point within `range` of the camera in view lies inside it).
  const double u0 = (-0.5 - camera.cx) / camera.fx;
  const double u1 = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double v0 = (-0.5 - camera.cy) / camera.fy;
  const double v1 = (camera.height - 0.5 - camera.cy) / camera.fy;
  const std::array<Eigen::Vector3d, 4> corners = {
      Eigen::Vector3d(u0, v0, 1.0), Eigen::Vector3d(u1, v0, 1.0), Eigen::Vector3d(u1, v1, 1.0),
      Eigen::Vector3d(u0, v1, 1.0)};
  std::array<Eigen::Vector3d, 4> normals;  // inward side planes through the camera, world frame
  Eigen::Vector3d lo = t, hi = t;
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector3d n = corners[i].cross(corners[(i + 1) % 4]).normalized();
    if (n.z() < 0.0) n = -n;  // the optical axis is inside
    normals[i] = R * n;
    const Eigen::Vector3d far = R * (corners[i] * range) + t;
    lo = lo.cwiseMin(far);
    hi = hi.cwiseMax(far);
  }
  lo = lo.cwiseMax(t - Eigen::Vector3d::Constant(range));
  hi = hi.cwiseMin(t + Eigen::Vector3d::Constant(range));
  const double res = config_.resolution_m;
  const double zres = config_.z_resolution_m;
  const double ox = windowOriginX();
  const double oy = windowOriginY();
  const double oz = config_.origin_z_m;
  const auto index = [](double v, double origin, double step, int n) {
    return static_cast<int>(std::clamp(std::floor((v - origin) / step), -1.0, double(n)));
  };
  const int ix0 = std::max(0, index(lo.x(), ox, res, nx_));
  const int ix1 = std::min(nx_ - 1, index(hi.x(), ox, res, nx_));
  const int iy0 = std::max(0, index(lo.y(), oy, res, ny_));
  const int iy1 = std::min(ny_ - 1, index(hi.y(), oy, res, ny_));
  const int iz0 = std::max(0, index(lo.z(), oz, zres, config_.z_voxels));
  const int iz1 = std::min(config_.z_voxels - 1, index(hi.z(), oz, zres, config_.z_voxels));
  if (ix0 > ix1 || iy0 > iy1 || iz0 > iz1) return;

  // Camera-from-world in float for the per-voxel loop; the voxel centres are taken relative to
  // the window origin, so the floats stay small.
  const Eigen::Matrix3f A = R.transpose().cast<float>();
  const Eigen::Vector3f cam_in_window((t.x() - ox), (t.y() - oy), (t.z() - oz));
  const Eigen::Vector3f b = -(A * cam_in_window);
  const auto fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const auto cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const float margin = static_cast<float>(0.5 * std::sqrt(2.0 * res * res + zres * zres));
  const auto clear2 = static_cast<float>(rays.raytrace_max_range_m * rays.raytrace_max_range_m);
  const auto none2 = static_cast<float>(rays.no_return_range_m * rays.no_return_range_m);
  const auto fres = static_cast<float>(res), fzres = static_cast<float>(zres);
  const int width = camera.width, height = camera.height;
  constexpr int kE = VoxelBlock::kEdge;
  const double block_radius =
      0.5 * std::sqrt(2.0 * (kE * res) * (kE * res) + (kE * zres) * (kE * zres));
  std::size_t visited = 0;
  const bool skip_saturated = config_.decay_time_s <= 0.0;
  const auto clamp_min = static_cast<float>(config_.log_odds.clamp_min);
  for (int bz = iz0 / kE; bz <= iz1 / kE; ++bz) {
    for (int by = (iy0 + y0_) >> VoxelBlock::kEdgeShift;
         by <= (iy1 + y0_) >> VoxelBlock::kEdgeShift; ++by) {
      for (int bx = (ix0 + x0_) >> VoxelBlock::kEdgeShift;
           bx <= (ix1 + x0_) >> VoxelBlock::kEdgeShift; ++bx) {
        // Block centre (world) against the pyramid's side planes and the range.
        const Eigen::Vector3d centre(anchor_x_ + (bx * kE + 0.5 * kE) * res,
                                     anchor_y_ + (by * kE + 0.5 * kE) * res,
                                     oz + (bz * kE + 0.5 * kE) * zres);
        const Eigen::Vector3d rel = centre - t;
        if (rel.norm() > range + block_radius) continue;
        bool outside = false;
        for (const auto& n : normals) outside = outside || n.dot(rel) < -block_radius;
        if (outside) continue;
        // The block's voxels inside the window and the index box.
        const int xa = std::max(ix0, bx * kE - x0_), xb = std::min(ix1, bx * kE + kE - 1 - x0_);
        const int ya = std::max(iy0, by * kE - y0_), yb = std::min(iy1, by * kE + kE - 1 - y0_);
        const int za = std::max(iz0, bz * kE), zb = std::min(iz1, bz * kE + kE - 1);
        VoxelBlock* block = blockAt(xa, ya, za);
        for (int z = za; z <= zb; ++z) {
          const float pz = (z + 0.5f) * fzres;
          for (int y = ya; y <= yb; ++y) {
            const float py = (y + 0.5f) * fres;
            const Eigen::Vector3f base = A.col(1) * py + A.col(2) * pz + b;
            for (int x = xa; x <= xb; ++x) {
              ++visited;
              const Eigen::Vector3f q = base + A.col(0) * ((x + 0.5f) * fres);
              if (!(q.z() > 0.0f)) continue;
              const float iz = 1.0f / q.z();
              const float uf = fx * q.x() * iz + cx + 0.5f;
              const float vf = fy * q.y() * iz + cy + 0.5f;
              if (!(uf >= 0.0f && vf >= 0.0f && uf < width && vf < height)) continue;
              const float d =
                  depth_m[static_cast<std::size_t>(vf) * width + static_cast<std::size_t>(uf)];
              const float r2 = q.squaredNorm();
              bool clear = false;
              if (validDepth(d)) {
                clear = q.z() < d - margin && r2 <= clear2;
              } else if (noReturn(d, zero_is_no_return)) {
                clear = r2 <= none2;
              }
              if (!clear) continue;
              // Already saturated free and nothing decays: another miss changes nothing, so it
              // is not written (nor reported as touched: the costmap would redraw the whole
              // view every frame).
              if (skip_saturated && block != nullptr &&
                  block->log_odds[voxelIndex(x + x0_, y + y0_, z)] <= clamp_min) {
                continue;
              }
              if (block == nullptr) {
                block = ensureBlock(x, y, z);
                if (block == nullptr) {
                  ++stats->dropped_updates;
                  continue;
                }
              }
              updateVoxel(block, voxelIndex(x + x0_, y + y0_, z), x, y, miss_, stamp, stats);
            }
          }
        }
      }
    }
  }
  stats->voxels_walked += visited;
}

}  // namespace downstream_perception
