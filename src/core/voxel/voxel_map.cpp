#include "downstream_perception/core/voxel/voxel_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "downstream_perception/core/grid/cost_values.h"
#include "downstream_perception/core/voxel/voxel_traversal.h"

namespace downstream_perception {

namespace {

// Window offsets are bounded so that offset + size and offset * resolution stay exact in int and
// double alike.
constexpr int kMaxWindowOffset = 1 << 30;

int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

std::string windowProblem(int x0, int y0, int nx, int ny) {
  std::ostringstream why;
  if (nx < 1 || ny < 1 || nx > VoxelBox::kMaxVoxelsPerAxis || ny > VoxelBox::kMaxVoxelsPerAxis) {
    why << "window must be 1 to " << VoxelBox::kMaxVoxelsPerAxis << " voxels per axis, got " << nx
        << " x " << ny;
  } else if (std::abs(std::int64_t{x0}) > kMaxWindowOffset ||
             std::abs(std::int64_t{y0}) > kMaxWindowOffset) {
    why << "window offset must be within +-" << kMaxWindowOffset << " voxels, got (" << x0 << ", "
        << y0 << ")";
  }
  return why.str();
}

// Bytes of the block pointer table a window needs (it counts against max_memory_mib too: a
// 65536 x 65536 window would need a gigabyte of null pointers).
std::int64_t tableBytes(int x0, int y0, int nx, int ny, int z_voxels) {
  constexpr int kE = VoxelBlock::kEdge;
  const std::int64_t nbx = floorDiv(x0 + nx - 1, kE) - floorDiv(x0, kE) + 1;
  const std::int64_t nby = floorDiv(y0 + ny - 1, kE) - floorDiv(y0, kE) + 1;
  const std::int64_t nbz = (z_voxels + kE - 1) / kE;
  return nbx * nby * nbz * static_cast<std::int64_t>(sizeof(std::unique_ptr<VoxelBlock>));
}

std::string tableProblem(const VoxelMapConfig& c, int x0, int y0, int nx, int ny) {
  const std::int64_t bytes = tableBytes(x0, y0, nx, ny, c.z_voxels);
  if (static_cast<double>(bytes) > c.max_memory_mib * 1048576.0) {
    std::ostringstream why;
    why << "a " << nx << " x " << ny << " x " << c.z_voxels << " voxel window needs " << bytes
        << " bytes of block table alone, more than max_memory_mib " << c.max_memory_mib;
    return why.str();
  }
  return "";
}

}  // namespace

std::string VoxelMapConfig::validate() const {
  std::ostringstream why;
  const auto positive = [](double v, double max) {
    return std::isfinite(v) && v > 0.0 && v <= max;
  };
  if (!positive(resolution_m, 100.0)) {
    why << "resolution_m must be in (0, 100] m, got " << resolution_m;
  } else if (!positive(z_resolution_m, 100.0)) {
    why << "z_resolution_m must be in (0, 100] m, got " << z_resolution_m;
  } else if (!std::isfinite(origin_z_m) || std::abs(origin_z_m) > 1e6) {
    why << "origin_z_m must be finite and within +-1e6 m, got " << origin_z_m;
  } else if (z_voxels < 1 || z_voxels > kMaxZVoxels) {
    why << "z_voxels must be in [1, " << kMaxZVoxels << "], got " << z_voxels;
  } else if (mark_threshold < 0) {
    why << "mark_threshold must be >= 0 voxels, got " << mark_threshold;
  } else if (unknown_threshold < 0) {
    why << "unknown_threshold must be >= 0 voxels, got " << unknown_threshold;
  } else if (!std::isfinite(min_obstacle_height_m) || !std::isfinite(max_obstacle_height_m) ||
             min_obstacle_height_m > max_obstacle_height_m) {
    why << "height band [min_obstacle_height_m, max_obstacle_height_m] must be finite with min <= "
           "max, got ["
        << min_obstacle_height_m << ", " << max_obstacle_height_m << "]";
  } else if (!std::isfinite(decay_time_s) || decay_time_s < 0.0) {
    why << "decay_time_s must be finite and >= 0 s (0 = off), got " << decay_time_s;
  } else if (!std::isfinite(max_memory_mib) || max_memory_mib < 0.01 || max_memory_mib > 65536.0) {
    why << "max_memory_mib must be in [0.01, 65536] MiB, got " << max_memory_mib;
  } else {
    const std::string model = log_odds.validate();
    if (!model.empty()) {
      why << "log_odds: " << model;
    } else {
      // The band must hold at least one voxel centre, or every column would project as free.
      const double lo = std::ceil((min_obstacle_height_m - origin_z_m) / z_resolution_m - 0.5);
      const double hi = std::floor((max_obstacle_height_m - origin_z_m) / z_resolution_m - 0.5);
      if (std::max(lo, 0.0) > std::min(hi, z_voxels - 1.0)) {
        why << "height band [" << min_obstacle_height_m << ", " << max_obstacle_height_m
            << "] m holds no voxel centre of the column (" << origin_z_m << " m + " << z_voxels
            << " x " << z_resolution_m << " m)";
      }
    }
  }
  return why.str();
}

std::string VoxelRayConfig::validate() const {
  std::ostringstream why;
  const auto range = [](double v) { return std::isfinite(v) && v >= 0.0 && v <= 1e4; };
  if (!range(obstacle_max_range_m)) {
    why << "obstacle_max_range_m must be in [0, 1e4] m, got " << obstacle_max_range_m;
  } else if (!range(raytrace_max_range_m)) {
    why << "raytrace_max_range_m must be in [0, 1e4] m, got " << raytrace_max_range_m;
  } else if (!range(no_return_range_m)) {
    why << "no_return_range_m must be in [0, 1e4] m, got " << no_return_range_m;
  }
  return why.str();
}

VoxelMap::VoxelMap(const VoxelMapConfig& config, double anchor_x_m, double anchor_y_m, int nx,
                   int ny)
    : config_(config), anchor_x_(anchor_x_m), anchor_y_(anchor_y_m) {
  std::string why = config.validate();
  if (why.empty() && (!std::isfinite(anchor_x_m) || !std::isfinite(anchor_y_m) ||
                      std::abs(anchor_x_m) > 1e9 || std::abs(anchor_y_m) > 1e9)) {
    why = "anchor must be finite and within +-1e9 m, got (" + std::to_string(anchor_x_m) + ", " +
          std::to_string(anchor_y_m) + ")";
  }
  if (why.empty()) why = windowProblem(0, 0, nx, ny);
  if (why.empty()) why = tableProblem(config, 0, 0, nx, ny);
  if (!why.empty()) throw std::invalid_argument("voxel map: " + why);
  hit_ = static_cast<float>(LogOddsGrid::logOddsOf(config.log_odds.p_hit));
  miss_ = static_cast<float>(LogOddsGrid::logOddsOf(config.log_odds.p_miss));
  const double zr = config.z_resolution_m;
  band_first_ = static_cast<int>(
      std::max(0.0, std::ceil((config.min_obstacle_height_m - config.origin_z_m) / zr - 0.5)));
  band_last_ = static_cast<int>(
      std::min<double>(config.z_voxels - 1,
                       std::floor((config.max_obstacle_height_m - config.origin_z_m) / zr - 0.5)));
  nbz_ = (config.z_voxels + VoxelBlock::kEdge - 1) / VoxelBlock::kEdge;
  rebuildTable(0, 0, nx, ny);
}

void VoxelMap::setWindow(int x0, int y0, int nx, int ny) {
  std::string why = windowProblem(x0, y0, nx, ny);
  if (why.empty()) why = tableProblem(config_, x0, y0, nx, ny);
  if (!why.empty()) throw std::invalid_argument("voxel map: " + why);
  if (x0 == x0_ && y0 == y0_ && nx == nx_ && ny == ny_) return;
  rebuildTable(x0, y0, nx, ny);
}

void VoxelMap::rebuildTable(int x0, int y0, int nx, int ny) {
  constexpr int kE = VoxelBlock::kEdge;
  const int bx0 = floorDiv(x0, kE);
  const int by0 = floorDiv(y0, kE);
  const int nbx = floorDiv(x0 + nx - 1, kE) - bx0 + 1;
  const int nby = floorDiv(y0 + ny - 1, kE) - by0 + 1;
  std::vector<std::unique_ptr<VoxelBlock>> table(static_cast<std::size_t>(nbx) * nby * nbz_);
  std::size_t kept = 0;
  for (int bz = 0; bz < nbz_ && !table_.empty(); ++bz) {
    for (int by = 0; by < nby_; ++by) {
      for (int bx = 0; bx < nbx_; ++bx) {
        auto& old = table_[(static_cast<std::size_t>(bz) * nby_ + by) * nbx_ + bx];
        if (!old) continue;
        const int gbx = bx0_ + bx - bx0;
        const int gby = by0_ + by - by0;
        if (gbx < 0 || gby < 0 || gbx >= nbx || gby >= nby) continue;  // freed with the old table
        // Voxels of a kept block that are outside the new window are forgotten.
        for (int v = 0; v < VoxelBlock::kVoxels; ++v) {
          const int gx = (bx0 + gbx) * kE + (v & (kE - 1));
          const int gy = (by0 + gby) * kE + ((v >> VoxelBlock::kEdgeShift) & (kE - 1));
          if (gx < x0 || gx >= x0 + nx || gy < y0 || gy >= y0 + ny) {
            old->log_odds[v] = 0.0f;
            old->frame[v] = 0;
          }
        }
        table[(static_cast<std::size_t>(bz) * nby + gby) * nbx + gbx] = std::move(old);
        ++kept;
      }
    }
  }
  table_ = std::move(table);
  blocks_ = kept;
  // The blocks get what the table leaves of the budget. Blocks kept beyond it (a window grown in
  // place) stay; no new one is taken until they are fewer.
  const double left =
      config_.max_memory_mib * 1048576.0 - static_cast<double>(table_.size() * sizeof(table_[0]));
  max_blocks_ = static_cast<std::size_t>(std::max(0.0, left) / sizeof(VoxelBlock));
  x0_ = x0;
  y0_ = y0;
  nx_ = nx;
  ny_ = ny;
  bx0_ = bx0;
  by0_ = by0;
  nbx_ = nbx;
  nby_ = nby;
}

VoxelBlock* VoxelMap::blockAt(int x, int y, int z) const {
  const int gx = x + x0_;
  const int gy = y + y0_;
  const int bx = (gx >> VoxelBlock::kEdgeShift) - bx0_;  // arithmetic shift = floor division
  const int by = (gy >> VoxelBlock::kEdgeShift) - by0_;
  const int bz = z >> VoxelBlock::kEdgeShift;
  return table_[(static_cast<std::size_t>(bz) * nby_ + by) * nbx_ + bx].get();
}

VoxelBlock* VoxelMap::ensureBlock(int x, int y, int z) {
  const int bx = ((x + x0_) >> VoxelBlock::kEdgeShift) - bx0_;
  const int by = ((y + y0_) >> VoxelBlock::kEdgeShift) - by0_;
  const int bz = z >> VoxelBlock::kEdgeShift;
  auto& slot = table_[(static_cast<std::size_t>(bz) * nby_ + by) * nbx_ + bx];
  if (!slot) {
    if (blocks_ >= max_blocks_) return nullptr;
    slot = std::make_unique<VoxelBlock>();
    ++blocks_;
  }
  return slot.get();
}

double VoxelMap::effective(const VoxelBlock& b, int v, double now_s) const {
  const double l = b.log_odds[v];
  if (config_.decay_time_s <= 0.0 || l == 0.0) return l;
  const double dt = (now_s - epoch_s_) - b.stamp_s[v];
  if (!(dt > 0.0)) return l;  // time went back (or NaN): no decay
  return l * std::exp(-dt / config_.decay_time_s);
}

void VoxelMap::update(int x, int y, int z, float delta, float stamp, VoxelIntegrationStats* stats) {
  VoxelBlock* b = ensureBlock(x, y, z);
  if (b == nullptr) {
    ++stats->dropped_updates;
    return;
  }
  updateVoxel(b, voxelIndex(x + x0_, y + y0_, z), x, y, delta, stamp, stats);
}

void VoxelMap::updateVoxel(VoxelBlock* b, int v, int x, int y, float delta, float stamp,
                           VoxelIntegrationStats* stats) {
  if (b->frame[v] == frame_) return;  // updated by this frame already (hits first)
  b->frame[v] = frame_;
  double l = b->log_odds[v];
  if (config_.decay_time_s > 0.0 && l != 0.0) {
    const double dt = static_cast<double>(stamp) - b->stamp_s[v];
    if (dt > 0.0) l *= std::exp(-dt / config_.decay_time_s);
  }
  l = std::clamp(l + delta, config_.log_odds.clamp_min, config_.log_odds.clamp_max);
  b->log_odds[v] = static_cast<float>(l);
  b->stamp_s[v] = stamp;
  if (delta > 0.0f) {
    ++stats->marked;
  } else {
    ++stats->cleared;
  }
  stats->touched.expand(x, y);
}

void VoxelMap::clearRay(const double p0[3], const double p1[3], bool include_end, float stamp,
                        bool one_per_end_voxel, VoxelIntegrationStats* stats) {
  const VoxelBox box{nx_, ny_, config_.z_voxels};
  // one_per_end_voxel: false if a ray of this frame ended in voxel e already (else claims it).
  const auto first_to_end_in = [this](int ex, int ey, int ez) {
    VoxelBlock* b = ensureBlock(ex, ey, ez);
    if (b == nullptr) return true;  // no room to remember it: cast the ray
    const int v = voxelIndex(ex + x0_, ey + y0_, ez);
    if (b->ray_frame[v] == frame_) return false;
    b->ray_frame[v] = frame_;
    return true;
  };
  const bool end_inside = p1[0] >= 0.0 && p1[1] >= 0.0 && p1[2] >= 0.0 && p1[0] < nx_ &&
                          p1[1] < ny_ && p1[2] < config_.z_voxels;
  if (one_per_end_voxel && end_inside) {
    // Decided before the clip (most rays of a depth image are repeats): the end voxel is the one
    // the walk ends in, the same rounding.
    const auto cell = [p1](int a, int n) {
      return static_cast<int>(FixedSegment::toFixed(p1[a], n) >> FixedSegment::kShift);
    };
    if (!first_to_end_in(cell(0, nx_), cell(1, ny_), cell(2, config_.z_voxels))) return;
  }
  FixedSegment s;
  bool end_clipped = false;
  if (!clipToFixed(box, p0, p1, &s, &end_clipped)) return;
  const VoxelWalk walk(s);
  if (one_per_end_voxel && !end_inside) {
    const auto e = walk.end();
    if (!first_to_end_in(e[0], e[1], e[2])) return;
  }
  // Consecutive voxels of a ray mostly share a block: its pointer is looked up once per block.
  VoxelBlock* block = nullptr;
  int cached_key[3] = {std::numeric_limits<int>::min(), 0, 0};
  const int x0 = x0_;
  const int y0 = y0_;
  const std::uint32_t frame = frame_;
  const int n = walk.walk(include_end || end_clipped, [&](int x, int y, int z) {
    const int gx = x + x0;
    const int gy = y + y0;
    const int key[3] = {gx >> VoxelBlock::kEdgeShift, gy >> VoxelBlock::kEdgeShift,
                        z >> VoxelBlock::kEdgeShift};
    if (key[0] != cached_key[0] || key[1] != cached_key[1] || key[2] != cached_key[2]) {
      block = ensureBlock(x, y, z);
      std::copy(key, key + 3, cached_key);
    }
    if (block == nullptr) {
      ++stats->dropped_updates;
      return;
    }
    const int v = voxelIndex(gx, gy, z);
    if (block->frame[v] == frame) return;  // the common case: updated by this frame already
    updateVoxel(block, v, x, y, miss_, stamp, stats);
  });
  stats->voxels_walked += static_cast<std::size_t>(n);
}

float VoxelMap::beginFrame(double stamp_s) {
  if (!has_epoch_) {
    // Stamps are kept as float seconds since the first frame: 1 ms resolution for ~4.6 hours.
    epoch_s_ = stamp_s;
    has_epoch_ = true;
  }
  if (++frame_ == 0) {
    // 2^32 frames: reset the tags so that no voxel looks updated by the new frame already.
    for (auto& b : table_) {
      if (!b) continue;
      std::fill(std::begin(b->frame), std::end(b->frame), 0u);
      std::fill(std::begin(b->ray_frame), std::end(b->ray_frame), 0u);
    }
    frame_ = 1;
  }
  return static_cast<float>(stamp_s - epoch_s_);
}

VoxelIntegrationStats VoxelMap::integrate(const Eigen::Vector3d& origin, const float* hits,
                                          std::size_t n_hits, const float* no_returns,
                                          std::size_t n_no_returns, double stamp_s,
                                          const VoxelRayConfig& rays) {
  if (!origin.allFinite()) throw std::invalid_argument("voxel map: sensor origin is not finite");
  if (!std::isfinite(stamp_s)) throw std::invalid_argument("voxel map: stamp is not finite");
  const std::string why = rays.validate();
  if (!why.empty()) throw std::invalid_argument("voxel map: " + why);
  if ((hits == nullptr && n_hits > 0) || (no_returns == nullptr && n_no_returns > 0)) {
    throw std::invalid_argument("voxel map: null point array with a non-zero count");
  }
  VoxelIntegrationStats stats;
  stats.rays = n_hits + n_no_returns;
  const float stamp = beginFrame(stamp_s);
  const double res = config_.resolution_m;
  const double zres = config_.z_resolution_m;
  const double ox = windowOriginX();
  const double oy = windowOriginY();
  const double oz = config_.origin_z_m;
  const double o_units[3] = {(origin.x() - ox) / res, (origin.y() - oy) / res,
                             (origin.z() - oz) / zres};
  const auto units = [&](const Eigen::Vector3d& p, double out[3]) {
    out[0] = (p.x() - ox) / res;
    out[1] = (p.y() - oy) / res;
    out[2] = (p.z() - oz) / zres;
  };
  const auto point = [](const float* xyz, std::size_t i) {
    return Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  };
  // Pass 1: hits mark (and claim their voxel for this frame).
  if (rays.marking) {
    for (std::size_t i = 0; i < n_hits; ++i) {
      const Eigen::Vector3d p = point(hits, i);
      const double dist = (p - origin).norm();
      // A point at the origin has no direction: counted invalid by the clearing pass below.
      if (!p.allFinite() || !(dist > 0.0) || dist > rays.obstacle_max_range_m) continue;
      double u[3];
      units(p, u);
      if (!(u[0] >= 0.0 && u[1] >= 0.0 && u[2] >= 0.0 && u[0] < nx_ && u[1] < ny_ &&
            u[2] < config_.z_voxels)) {
        continue;
      }
      // The walk's end voxel (the same rounding), so that the mark is exactly the voxel the
      // clearing ray stops at.
      const auto cell = [&u](int a, int n) {
        return static_cast<int>(FixedSegment::toFixed(u[a], n) >> FixedSegment::kShift);
      };
      update(cell(0, nx_), cell(1, ny_), cell(2, config_.z_voxels), hit_, stamp, &stats);
    }
  }
  // Pass 2: every ray clears up to its return / range.
  for (std::size_t i = 0; i < n_hits; ++i) {
    const Eigen::Vector3d p = point(hits, i);
    const Eigen::Vector3d d = p - origin;
    const double dist = d.norm();
    if (!p.allFinite() || !(dist > 0.0) || !std::isfinite(dist)) {
      ++stats.invalid_points;
      continue;
    }
    if (!rays.clearing || rays.raytrace_max_range_m <= 0.0) continue;
    const Eigen::Vector3d end =
        dist <= rays.raytrace_max_range_m ? p : origin + d * (rays.raytrace_max_range_m / dist);
    double u[3];
    units(end, u);
    clearRay(o_units, u, false, stamp, rays.one_ray_per_end_voxel, &stats);
  }
  for (std::size_t i = 0; i < n_no_returns; ++i) {
    const Eigen::Vector3d d = point(no_returns, i) - origin;
    const double dist = d.norm();
    if (!d.allFinite() || !(dist > 0.0) || !std::isfinite(dist)) {
      ++stats.invalid_points;
      continue;
    }
    if (!rays.clearing || rays.no_return_range_m <= 0.0) continue;
    double u[3];
    units(origin + d * (rays.no_return_range_m / dist), u);
    clearRay(o_units, u, true, stamp, rays.one_ray_per_end_voxel, &stats);
  }
  return stats;
}

VoxelIntegrationStats VoxelMap::clearColumns(const std::vector<std::pair<int, int>>& columns,
                                             double stamp_s) {
  if (!std::isfinite(stamp_s)) throw std::invalid_argument("voxel map: stamp is not finite");
  VoxelIntegrationStats stats;
  if (columns.empty()) return stats;
  const float stamp = beginFrame(stamp_s);
  const auto floor = static_cast<float>(config_.log_odds.clamp_min);
  // Any delta this negative clamps to the minimum in updateVoxel().
  const auto to_floor =
      static_cast<float>(config_.log_odds.clamp_min - config_.log_odds.clamp_max - 1.0);
  for (const auto& [x, y] : columns) {
    if (x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
    for (int z = band_first_; z <= band_last_; ++z) {
      const VoxelBlock* b = blockAt(x, y, z);
      if (b != nullptr && config_.decay_time_s <= 0.0 &&
          b->log_odds[voxelIndex(x + x0_, y + y0_, z)] <= floor) {
        continue;
      }
      update(x, y, z, to_floor, stamp, &stats);
    }
  }
  return stats;
}

double VoxelMap::logOdds(int x, int y, int z, double now_s) const {
  if (x < 0 || y < 0 || z < 0 || x >= nx_ || y >= ny_ || z >= config_.z_voxels) return 0.0;
  const VoxelBlock* b = blockAt(x, y, z);
  if (b == nullptr) return 0.0;
  return effective(*b, voxelIndex(x + x0_, y + y0_, z), now_s);
}

VoxelState VoxelMap::state(int x, int y, int z, double now_s) const {
  const double l = logOdds(x, y, z, now_s);
  if (l > config_.log_odds.occupied_threshold) return VoxelState::kOccupied;
  if (l < config_.log_odds.free_threshold) return VoxelState::kFree;
  return VoxelState::kUnknown;
}

VoxelColumn VoxelMap::column(int x, int y, double now_s) const {
  VoxelColumn c;
  for (int z = band_first_; z <= band_last_; ++z) {
    const VoxelState s = state(x, y, z, now_s);
    if (s == VoxelState::kOccupied) ++c.occupied;
    if (s == VoxelState::kUnknown) ++c.unknown;
  }
  return c;
}

int VoxelMap::unknownCount(const VoxelColumn& c) const {
  // costmap_2d keeps 16 bits per column whatever z_voxels is, and the bits above the column are
  // never known: it compares unknown_threshold with 16 minus the known voxels. So with its
  // defaults (10 voxels, threshold 15) a column no ray has touched stays unknown and one known
  // voxel makes it free. A band of more than 16 voxels (ours) counts its own unknown voxels.
  const int band = band_last_ - band_first_ + 1;
  return c.unknown + std::max(0, kCostmap2dColumnBits - band);
}

std::uint8_t VoxelMap::columnCost(const VoxelColumn& c) const {
  if (c.occupied > config_.mark_threshold) return cost::kLethalObstacle;
  if (unknownCount(c) <= config_.unknown_threshold) return cost::kFreeSpace;
  return cost::kNoInformation;
}

void VoxelMap::project(double now_s, std::vector<std::uint8_t>* costs) const {
  costs->assign(static_cast<std::size_t>(nx_) * ny_, 0);
  project(now_s, CellBounds{0, 0, nx_ - 1, ny_ - 1}, costs);
}

void VoxelMap::project(double now_s, const CellBounds& window,
                       std::vector<std::uint8_t>* costs) const {
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;
  if (costs->size() != cells) costs->assign(cells, 0);
  if (window.empty()) return;
  const int x0 = std::max(0, window.min_x), x1 = std::min(nx_ - 1, window.max_x);
  const int y0 = std::max(0, window.min_y), y1 = std::min(ny_ - 1, window.max_y);
  const int band = band_last_ - band_first_ + 1;
  const VoxelColumn unseen{0, band};
  const std::uint8_t unseen_cost = columnCost(unseen);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      // Most columns have no block at all in the band: one or two null pointers decide them.
      bool any = false;
      for (int bz = band_first_ >> VoxelBlock::kEdgeShift;
           bz <= (band_last_ >> VoxelBlock::kEdgeShift) && !any; ++bz) {
        any = blockAt(x, y, bz << VoxelBlock::kEdgeShift) != nullptr;
      }
      (*costs)[static_cast<std::size_t>(y) * nx_ + x] =
          any ? columnCost(column(x, y, now_s)) : unseen_cost;
    }
  }
}

std::vector<Eigen::Vector3f> VoxelMap::occupiedCentres(double now_s) const {
  std::vector<Eigen::Vector3f> out;
  const double res = config_.resolution_m;
  const double zres = config_.z_resolution_m;
  constexpr int kE = VoxelBlock::kEdge;
  for (int bz = 0; bz < nbz_; ++bz) {
    for (int by = 0; by < nby_; ++by) {
      for (int bx = 0; bx < nbx_; ++bx) {
        const VoxelBlock* b = table_[(static_cast<std::size_t>(bz) * nby_ + by) * nbx_ + bx].get();
        if (b == nullptr) continue;
        for (int v = 0; v < VoxelBlock::kVoxels; ++v) {
          if (b->log_odds[v] <= config_.log_odds.occupied_threshold) continue;  // decay only lowers
          if (effective(*b, v, now_s) <= config_.log_odds.occupied_threshold) continue;
          const int gx = (bx0_ + bx) * kE + (v & (kE - 1));
          const int gy = (by0_ + by) * kE + ((v >> VoxelBlock::kEdgeShift) & (kE - 1));
          const int z = bz * kE + (v >> (2 * VoxelBlock::kEdgeShift));
          if (z >= config_.z_voxels) continue;
          out.emplace_back(static_cast<float>(anchor_x_ + (gx + 0.5) * res),
                           static_cast<float>(anchor_y_ + (gy + 0.5) * res),
                           static_cast<float>(config_.origin_z_m + (z + 0.5) * zres));
        }
      }
    }
  }
  return out;
}

std::size_t VoxelMap::prune(double now_s) {
  std::size_t freed = 0;
  for (auto& b : table_) {
    if (!b) continue;
    bool known = false;
    for (int v = 0; v < VoxelBlock::kVoxels && !known; ++v) {
      const double l = effective(*b, v, now_s);
      known = l > config_.log_odds.occupied_threshold || l < config_.log_odds.free_threshold;
    }
    if (!known) {
      b.reset();
      --blocks_;
      ++freed;
    }
  }
  return freed;
}

void VoxelMap::clear() {
  for (auto& b : table_) b.reset();
  blocks_ = 0;
}

}  // namespace downstream_perception
