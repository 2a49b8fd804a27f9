#include "downstream_perception/core/tsdf/esdf.h"

#include <tsl/robin_set.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "downstream_perception/core/tsdf/distance_transform_3d.h"

namespace downstream_perception {

namespace {
/// A cluster of blocks to write whose region would hold more than kMaxRegionVoxels is split into
/// tiles of this many blocks per axis: this bounds the scratch memory.
constexpr int kTileBlocks = 8;
constexpr std::size_t kMaxRegionVoxels = std::size_t{1} << 24;
/// Largest dense block grid used to mark the blocks within reach of a change.
constexpr std::size_t kMaxMarkGridBlocks = std::size_t{1} << 22;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The transform's 16-bit results hold every radius the config allows (ceil(max + 1/2) voxels).
static_assert(EsdfConfig::kMaxDistanceVoxels + 1 <= kEdtMaxRadius16,
              "the ESDF's radius must fit the 16-bit distance transform");

std::size_t volume(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  if ((hi.array() < lo.array()).any()) return 0;
  const Eigen::Vector3i n = hi - lo + Eigen::Vector3i::Ones();
  return static_cast<std::size_t>(n.x()) * n.y() * n.z();
}

/// floor(a / b) for b > 0.
int floorDiv(int a, int b) {
  return a >= 0 ? a / b : -1 - (-(a + 1)) / b;
}
/// The blocks in 26-connected clusters (breadth-first over the block grid).
std::vector<std::vector<Eigen::Vector3i>> connectedClusters(
    const std::vector<Eigen::Vector3i>& keys) {
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> left(keys.begin(), keys.end());
  std::vector<std::vector<Eigen::Vector3i>> clusters;
  for (const Eigen::Vector3i& seed : keys) {
    if (left.erase(seed) == 0) continue;
    std::vector<Eigen::Vector3i> cluster{seed};
    for (std::size_t i = 0; i < cluster.size(); ++i) {
      const Eigen::Vector3i k = cluster[i];
      for (int z = -1; z <= 1; ++z) {
        for (int y = -1; y <= 1; ++y) {
          for (int x = -1; x <= 1; ++x) {
            const Eigen::Vector3i n = k + Eigen::Vector3i(x, y, z);
            if (left.erase(n) != 0) cluster.push_back(n);
          }
        }
      }
    }
    clusters.push_back(std::move(cluster));
  }
  return clusters;
}
}  // namespace

std::string EsdfConfig::validate(double voxel_size_m) const {
  std::ostringstream why;
  if (!(std::isfinite(voxel_size_m) && voxel_size_m > 0.0)) {
    why << "voxel_size_m must be finite and > 0, got " << voxel_size_m;
  } else if (!(std::isfinite(max_distance_m) && max_distance_m >= voxel_size_m &&
               max_distance_m <= kMaxDistanceVoxels * voxel_size_m)) {
    why << "esdf max_distance_m must be in [1, " << kMaxDistanceVoxels << "] voxels ("
        << voxel_size_m << " .. " << kMaxDistanceVoxels * voxel_size_m << " m), got "
        << max_distance_m;
  }
  return why.str();
}

EsdfState esdfStateOf(const TsdfVoxel& v, float min_weight) {
  if (!(v.observedWeight() > min_weight)) return EsdfState::kUnknown;
  return v.distance < 0.0f ? EsdfState::kOccupied : EsdfState::kFree;
}

float esdfMetres(std::int32_t squared_voxels, bool occupied, double voxel_size_m,
                 double max_distance_m) {
  const double magnitude =
      squared_voxels == kEdtFarSquared
          ? max_distance_m
          : std::min(max_distance_m,
                     (std::sqrt(static_cast<double>(squared_voxels)) - 0.5) * voxel_size_m);
  return static_cast<float>(occupied ? -magnitude : magnitude);
}

Esdf::Esdf(const EsdfConfig& config, double voxel_size_m) : voxel_size_m_(voxel_size_m) {
  setConfig(config);
}

void Esdf::setConfig(const EsdfConfig& config) {
  const std::string why = config.validate(voxel_size_m_);
  if (!why.empty()) throw std::invalid_argument("esdf: " + why);
  config_ = config;
  // A seed farther than this many voxels gives a value above the cap (sqrt(k) - 1/2 > max).
  radius_voxels_ = static_cast<int>(std::ceil(config.max_distance_m / voxel_size_m_ + 0.5));
  full_next_ = true;
}

EsdfUpdateStats Esdf::update(const TsdfMap& map) {
  return run(map, false);
}

EsdfUpdateStats Esdf::recompute(const TsdfMap& map) {
  return run(map, true);
}

std::size_t Esdf::readBlock(const TsdfMap& map, const Eigen::Vector3i& key, const TsdfBlock& block,
                            std::vector<Eigen::Vector3i>* changed) {
  std::unique_ptr<EsdfBlock>& esdf = blocks_[key];
  if (!esdf) {
    esdf = std::make_unique<EsdfBlock>();
    esdf->distance.fill(kNaN);
    esdf->state.fill(static_cast<std::uint8_t>(EsdfState::kUnknown));
  }
  const float min_weight = static_cast<float>(map.config().min_weight);
  std::size_t differ = 0;
  for (int i = 0; i < kTsdfBlockVoxels; ++i) {
    const auto s = static_cast<std::uint8_t>(esdfStateOf(block.voxels[i], min_weight));
    differ += s != esdf->state[i];
    esdf->state[i] = s;
  }
  if (differ > 0) changed->push_back(key);
  return differ;
}

EsdfUpdateStats Esdf::run(const TsdfMap& map, bool full) {
  if (map.voxelSize() != voxel_size_m_) {
    throw std::invalid_argument("esdf: the map's voxel size differs from the ESDF's");
  }
  EsdfUpdateStats stats;
  const float min_weight = static_cast<float>(map.config().min_weight);
  full = full || full_next_ || min_weight != seen_min_weight_;
  stats.full = full;
  std::vector<Eigen::Vector3i> changed;
  // Blocks the TSDF dropped (evicted, cleared): their voxels become unknown.
  for (auto it = blocks_.begin(); it != blocks_.end();) {
    if (map.find(it->first) != nullptr) {
      ++it;
      continue;
    }
    ++stats.blocks_removed;
    changed.push_back(it->first);
    for (const std::uint8_t st : it->second->state) {
      stats.voxels_changed += st != static_cast<std::uint8_t>(EsdfState::kUnknown);
    }
    it = blocks_.erase(it);
  }
  BlockBox extent{Eigen::Vector3i::Constant(std::numeric_limits<int>::max()),
                  Eigen::Vector3i::Constant(std::numeric_limits<int>::min())};
  for (const auto& [key, block] : map.blocks()) {
    extent.lo = extent.lo.cwiseMin(key);
    extent.hi = extent.hi.cwiseMax(key);
    if (!full && block->updated_stamp <= seen_generation_) continue;
    ++stats.blocks_read;
    stats.voxels_changed += readBlock(map, key, *block, &changed);
  }
  seen_generation_ = map.generation();
  seen_min_weight_ = min_weight;
  full_next_ = false;
  std::vector<Eigen::Vector3i> write;
  if (full) {
    write.reserve(blocks_.size());
    for (const auto& kv : blocks_) write.push_back(kv.first);
  } else {
    write = blocksToWrite(changed, extent);
  }
  if (write.empty()) return stats;
  stats.blocks_written = write.size();

  computeRegions(write, extent, &stats);
  return stats;
}

void Esdf::computeRegions(const std::vector<Eigen::Vector3i>& write, const BlockBox& extent,
                          EsdfUpdateStats* stats) {
  // Each cluster of blocks to write is one region (scattered changes give small separate ones),
  // unless that region would hold more than kMaxRegionVoxels: then its tiles are.
  const int margin = (radius_voxels_ - 1) / kTsdfBlockSide + 1;  // blocks of seeds around them
  const auto boundsOf = [](const std::vector<Eigen::Vector3i>& keys) {
    BlockBox b{keys.front(), keys.front()};
    for (const Eigen::Vector3i& k : keys) {
      b.lo = b.lo.cwiseMin(k);
      b.hi = b.hi.cwiseMax(k);
    }
    return b;
  };
  for (const std::vector<Eigen::Vector3i>& cluster : connectedClusters(write)) {
    const BlockBox box = boundsOf(cluster);
    const std::size_t voxels =
        volume((box.lo - Eigen::Vector3i::Constant(margin)).cwiseMax(extent.lo),
               (box.hi + Eigen::Vector3i::Constant(margin)).cwiseMin(extent.hi)) *
        kTsdfBlockVoxels;
    if (voxels <= kMaxRegionVoxels) {
      computeRegion(box, cluster, extent, stats);
      continue;
    }
    tsl::robin_map<Eigen::Vector3i, std::vector<Eigen::Vector3i>, BlockIndexHash> tiles;
    for (const Eigen::Vector3i& key : cluster) {
      tiles[Eigen::Vector3i(floorDiv(key.x(), kTileBlocks), floorDiv(key.y(), kTileBlocks),
                            floorDiv(key.z(), kTileBlocks))]
          .push_back(key);
    }
    for (const auto& kv : tiles) computeRegion(boundsOf(kv.second), kv.second, extent, stats);
  }
}

std::vector<Eigen::Vector3i> Esdf::blocksToWrite(const std::vector<Eigen::Vector3i>& changed,
                                                 const BlockBox& extent) const {
  std::vector<Eigen::Vector3i> write;
  if (changed.empty() || blocks_.empty()) return write;
  // A voxel k blocks away along an axis is at least 8 (k - 1) + 1 voxels from every voxel of
  // the changed block: beyond the radius for k > reach.
  const Eigen::Vector3i reach =
      Eigen::Vector3i::Constant((radius_voxels_ - 1) / kTsdfBlockSide + 1);
  Eigen::Vector3i lo = changed.front(), hi = changed.front();
  for (const Eigen::Vector3i& k : changed) {
    lo = lo.cwiseMin(k);
    hi = hi.cwiseMax(k);
  }
  lo = (lo - reach).cwiseMax(extent.lo);
  hi = (hi + reach).cwiseMin(extent.hi);
  const std::size_t cells = volume(lo, hi);
  if (cells == 0) return write;
  if (cells <= kMaxMarkGridBlocks) {
    // Dense marks over the changed blocks' reach (a few thousand blocks in a room).
    const Eigen::Vector3i n = hi - lo + Eigen::Vector3i::Ones();
    std::vector<std::uint8_t> mark(cells, 0);
    for (const Eigen::Vector3i& k : changed) {
      const Eigen::Vector3i a = (k - reach).cwiseMax(lo) - lo;
      const Eigen::Vector3i b = (k + reach).cwiseMin(hi) - lo;
      // A block the TSDF dropped may lie beyond the map's extent on some axis (a cleared map
      // integrated again elsewhere): its reach then misses the grid, and the fill below would
      // run from past the end of a row.
      if ((a.array() > b.array()).any()) continue;
      for (int z = a.z(); z <= b.z(); ++z) {
        for (int y = a.y(); y <= b.y(); ++y) {
          std::uint8_t* row = mark.data() + (static_cast<std::size_t>(z) * n.y() + y) * n.x();
          std::fill(row + a.x(), row + b.x() + 1, std::uint8_t{1});
        }
      }
    }
    std::size_t i = 0;
    for (int z = 0; z < n.z(); ++z) {
      for (int y = 0; y < n.y(); ++y) {
        for (int x = 0; x < n.x(); ++x, ++i) {
          const Eigen::Vector3i key = lo + Eigen::Vector3i(x, y, z);
          if (mark[i] && blocks_.find(key) != blocks_.end()) write.push_back(key);
        }
      }
    }
    return write;
  }
  // Changes far apart (a huge, sparse map): look up each changed block's neighbours.
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> seen;
  for (const Eigen::Vector3i& k : changed) {
    for (int z = -reach.z(); z <= reach.z(); ++z) {
      for (int y = -reach.y(); y <= reach.y(); ++y) {
        for (int x = -reach.x(); x <= reach.x(); ++x) {
          const Eigen::Vector3i key = k + Eigen::Vector3i(x, y, z);
          if (blocks_.find(key) != blocks_.end() && seen.insert(key).second) write.push_back(key);
        }
      }
    }
  }
  return write;
}

void Esdf::computeRegion(const BlockBox& write_box,
                         const std::vector<Eigen::Vector3i>& write_blocks, const BlockBox& extent,
                         EsdfUpdateStats* stats) {
  const int margin = (radius_voxels_ - 1) / kTsdfBlockSide + 1;
  const Eigen::Vector3i lo = (write_box.lo - Eigen::Vector3i::Constant(margin)).cwiseMax(extent.lo);
  const Eigen::Vector3i hi = (write_box.hi + Eigen::Vector3i::Constant(margin)).cwiseMin(extent.hi);
  const Eigen::Vector3i size = (hi - lo + Eigen::Vector3i::Ones()) * kTsdfBlockSide;
  const std::size_t nx = size.x(), nxy = nx * size.y();
  labels_.assign(nxy * size.z(), static_cast<std::uint8_t>(EsdfState::kUnknown));
  ++stats->regions;
  stats->region_voxels += labels_.size();
  // Offset of a block's first voxel in the region.
  const auto offsetOf = [&](const Eigen::Vector3i& key) {
    const Eigen::Vector3i o = (key - lo) * kTsdfBlockSide;
    return o.x() + o.y() * nx + o.z() * nxy;
  };
  bool any_free = false, any_occupied = false;
  for (int bz = lo.z(); bz <= hi.z(); ++bz) {
    for (int by = lo.y(); by <= hi.y(); ++by) {
      for (int bx = lo.x(); bx <= hi.x(); ++bx) {
        const auto it = blocks_.find(Eigen::Vector3i(bx, by, bz));
        if (it == blocks_.end()) continue;
        const std::uint8_t* st = it->second->state.data();
        std::uint8_t* dst = labels_.data() + offsetOf(it->first);
        for (int z = 0; z < kTsdfBlockSide; ++z) {
          for (int y = 0; y < kTsdfBlockSide; ++y) {
            std::copy(st, st + kTsdfBlockSide, dst + y * nx + z * nxy);
            st += kTsdfBlockSide;
          }
        }
      }
    }
  }
  for (const Eigen::Vector3i& key : write_blocks) {
    for (const std::uint8_t st : blocks_.find(key)->second->state) {
      any_free |= st == static_cast<std::uint8_t>(EsdfState::kFree);
      any_occupied |= st == static_cast<std::uint8_t>(EsdfState::kOccupied);
    }
  }
  // Free voxels: distance to the nearest occupied voxel; occupied voxels: to the nearest free.
  for (const EsdfState target : {EsdfState::kFree, EsdfState::kOccupied}) {
    const bool occupied = target == EsdfState::kOccupied;
    if (!(occupied ? any_occupied : any_free)) continue;
    const auto seed = static_cast<std::uint8_t>(occupied ? EsdfState::kFree : EsdfState::kOccupied);
    boundedSquaredDistances3d(labels_.data(), size, seed, radius_voxels_, &squared_, &edt_scratch_);
    for (const Eigen::Vector3i& key : write_blocks) {
      EsdfBlock& block = *blocks_.find(key)->second;
      const std::int16_t* sq = squared_.data() + offsetOf(key);
      int i = 0;
      for (int z = 0; z < kTsdfBlockSide; ++z) {
        for (int y = 0; y < kTsdfBlockSide; ++y) {
          const std::int16_t* row = sq + y * nx + z * nxy;
          for (int x = 0; x < kTsdfBlockSide; ++x, ++i) {
            const auto st = static_cast<EsdfState>(block.state[i]);
            if (st == EsdfState::kUnknown) {
              block.distance[i] = kNaN;
            } else if (st == target) {
              block.distance[i] = esdfMetres(row[x] == kEdtFarSquared16 ? kEdtFarSquared : row[x],
                                             occupied, voxel_size_m_, config_.max_distance_m);
            }
          }
        }
      }
    }
  }
}

float Esdf::voxelDistance(const Eigen::Vector3i& voxel) const {
  const auto it = blocks_.find(TsdfMap::blockOf(voxel));
  return it == blocks_.end() ? kNaN : it->second->distance[TsdfMap::localIndex(voxel)];
}

EsdfState Esdf::voxelState(const Eigen::Vector3i& voxel) const {
  const auto it = blocks_.find(TsdfMap::blockOf(voxel));
  return it == blocks_.end()
             ? EsdfState::kUnknown
             : static_cast<EsdfState>(it->second->state[TsdfMap::localIndex(voxel)]);
}

EsdfSample Esdf::sample(const Eigen::Vector3d& p) const {
  EsdfSample out;
  const Eigen::Vector3d u = p / voxel_size_m_;
  const double limit = 0.5 * TsdfMap::kMaxVoxelIndex;
  const auto unobserved = [&out]() {
    out.distance = std::numeric_limits<double>::quiet_NaN();
    out.gradient.setConstant(std::numeric_limits<double>::quiet_NaN());
    return out;
  };
  if (!(u.array().abs() <= limit).all()) return unobserved();  // also NaN
  const Eigen::Vector3d floor = u.array().floor();
  const Eigen::Vector3i i0 = floor.cast<int>();
  const Eigen::Vector3d f = u - floor;
  double d[8];  // corner c at i0 + (c & 1, c >> 1 & 1, c >> 2 & 1)
  for (int c = 0; c < 8; ++c) {
    d[c] = voxelDistance(i0 + Eigen::Vector3i(c & 1, (c >> 1) & 1, (c >> 2) & 1));
    if (std::isnan(d[c])) return unobserved();
  }
  const double gx = 1.0 - f.x(), gy = 1.0 - f.y(), gz = 1.0 - f.z();
  const double c00 = d[0] * gx + d[1] * f.x(), c10 = d[2] * gx + d[3] * f.x();
  const double c01 = d[4] * gx + d[5] * f.x(), c11 = d[6] * gx + d[7] * f.x();
  const double c0 = c00 * gy + c10 * f.y(), c1 = c01 * gy + c11 * f.y();
  out.observed = true;
  out.distance = c0 * gz + c1 * f.z();
  out.gradient.x() = ((d[1] - d[0]) * gy * gz + (d[3] - d[2]) * f.y() * gz +
                      (d[5] - d[4]) * gy * f.z() + (d[7] - d[6]) * f.y() * f.z()) /
                     voxel_size_m_;
  out.gradient.y() = ((c10 - c00) * gz + (c11 - c01) * f.z()) / voxel_size_m_;
  out.gradient.z() = (c1 - c0) / voxel_size_m_;
  return out;
}

std::size_t Esdf::memoryBytes() const {
  return blocks_.size() * sizeof(EsdfBlock) +
         blocks_.bucket_count() * (sizeof(Eigen::Vector3i) + sizeof(void*) + sizeof(std::int32_t)) +
         labels_.capacity() + squared_.capacity() * sizeof(std::int16_t) + edt_scratch_.bytes();
}

}  // namespace downstream_perception
