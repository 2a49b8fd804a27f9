// Euclidean signed distance field (ESDF) computed from a TsdfMap, in the same sparse 8^3 blocks,
// exact on the voxel lattice and updated incrementally.
//
// Voxel states, read from the TSDF: unknown (weight <= min_weight), occupied (observed, D < 0:
// behind the surface; D = 0 is free, as in the mesher), free (observed, D >= 0). A free voxel
// stores +(sqrt(k) - 1/2) * voxel_size, where k is its exact squared lattice distance (voxels^2)
// to the nearest occupied voxel; an occupied voxel stores -(sqrt(k) - 1/2) * voxel_size with k
// to the nearest free voxel. The half voxel puts the zero level halfway between an occupied
// voxel and its free neighbour (where the TSDF's zero crossing lies on average), so the field
// is continuous with unit slope across the surface. Magnitudes are clamped at max_distance_m;
// unknown voxels are NaN, and neither unknown voxels nor unallocated space are seeds (unknown
// space is not an obstacle: check the query's `observed`).
//
// Incremental: update() re-reads only the TSDF blocks integrated since the last update (their
// updated_stamp) plus the blocks the TSDF dropped, finds the voxels whose state changed, and
// recomputes only the blocks within max_distance_m of them, by an exact bounded distance
// transform (distance_transform_3d.h) over those blocks plus a max_distance_m margin of seeds.
#pragma once

#include <tsl/robin_map.h>
#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/distance_transform_3d.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"

namespace downstream_perception {

struct EsdfConfig {
  /// Largest max_distance_m in voxels: it bounds the margin of every distance-transform region,
  /// so the scratch memory of one region (at most 2^24 voxels, or one 64-voxel tile plus a
  /// 104-voxel margin on each side; 9 bytes a voxel).
  static constexpr int kMaxDistanceVoxels = 100;
  /// Distances are clamped at this (m). Also the reach of a change: a voxel that changes state
  /// alters distances within this radius only.
  double max_distance_m = 1.0;
  /// Empty if valid for a map of voxel_size_m, else the reason: max_distance_m finite, at least
  /// one voxel and at most kMaxDistanceVoxels voxels.
  std::string validate(double voxel_size_m) const;
};

enum class EsdfState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

struct EsdfBlock {
  std::array<float, kTsdfBlockVoxels> distance;      ///< m; NaN = unknown
  std::array<std::uint8_t, kTsdfBlockVoxels> state;  ///< EsdfState of each voxel
};

struct EsdfUpdateStats {
  bool full = false;               ///< every block recomputed
  std::size_t blocks_read = 0;     ///< TSDF blocks re-read (integrated since the last update)
  std::size_t blocks_removed = 0;  ///< blocks the TSDF no longer has
  std::size_t voxels_changed = 0;  ///< voxels whose state changed
  std::size_t blocks_written = 0;  ///< blocks whose distances were recomputed
  std::size_t regions = 0;         ///< distance-transform regions
  std::size_t region_voxels = 0;   ///< voxels in those regions (seed margins included)
};

/// The interpolated field at a point.
struct EsdfSample {
  bool observed = false;  ///< all 8 surrounding voxels known; else distance/gradient are NaN
  double distance = 0.0;  ///< m, trilinear between the 8 voxel centres around the point
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  ///< of that trilinear interpolant
};

/// A voxel's state as the ESDF reads it from the TSDF: unknown at weight <= min_weight, else
/// occupied when D < 0, free otherwise.
EsdfState esdfStateOf(const TsdfVoxel& voxel, float min_weight);

/// The stored value of a voxel whose exact squared lattice distance to the nearest seed is
/// `squared_voxels` (kEdtFarSquared: none within the cap): (sqrt(k) - 1/2) * voxel_size_m,
/// clamped at max_distance_m, negative for an occupied voxel.
float esdfMetres(std::int32_t squared_voxels, bool occupied, double voxel_size_m,
                 double max_distance_m);

class Esdf {
 public:
  using BlockMap = tsl::robin_map<Eigen::Vector3i, std::unique_ptr<EsdfBlock>, BlockIndexHash>;

  /// Throws std::invalid_argument if config.validate(voxel_size_m) fails.
  Esdf(const EsdfConfig& config, double voxel_size_m);
  const EsdfConfig& config() const { return config_; }
  /// Throws (keeping the old config) if invalid; the next update() recomputes everything.
  void setConfig(const EsdfConfig& config);

  /// Brings the field up to date with `map` (always the same map, with this voxel size: else
  /// std::invalid_argument): recomputes only around voxels whose state changed since the last
  /// update. The first call, and the first after setConfig or a changed min_weight, is full.
  EsdfUpdateStats update(const TsdfMap& map);
  /// Re-reads every block and recomputes the whole field.
  EsdfUpdateStats recompute(const TsdfMap& map);

  /// Stored distance of a voxel (m), NaN if unknown or not allocated.
  float voxelDistance(const Eigen::Vector3i& voxel) const;
  EsdfState voxelState(const Eigen::Vector3i& voxel) const;
  /// Trilinear interpolation between the 8 voxel centres around p, and its gradient.
  EsdfSample sample(const Eigen::Vector3d& p) const;

  double voxelSize() const { return voxel_size_m_; }
  const BlockMap& blocks() const { return blocks_; }
  std::size_t blockCount() const { return blocks_.size(); }
  /// Bytes held: the blocks (at most one per TSDF block, so bounded by its max_blocks), the
  /// hash table and the distance-transform scratch buffers.
  std::size_t memoryBytes() const;
  /// The max_distance_m cap in whole voxels of lattice distance: ceil(max / voxel + 1/2).
  int radiusVoxels() const { return radius_voxels_; }

 private:
  /// A box of blocks (inclusive block indices).
  struct BlockBox {
    Eigen::Vector3i lo, hi;
  };
  EsdfUpdateStats run(const TsdfMap& map, bool full);
  /// Reads a TSDF block's voxel states into its ESDF block (created if new); returns how many
  /// changed, and appends the key to `changed` if any did.
  std::size_t readBlock(const TsdfMap& map, const Eigen::Vector3i& key, const TsdfBlock& block,
                        std::vector<Eigen::Vector3i>* changed);
  std::vector<Eigen::Vector3i> blocksToWrite(const std::vector<Eigen::Vector3i>& changed,
                                             const BlockBox& extent) const;
  void computeRegions(const std::vector<Eigen::Vector3i>& write, const BlockBox& extent,
                      EsdfUpdateStats* stats);
  void computeRegion(const BlockBox& write_box, const std::vector<Eigen::Vector3i>& write_blocks,
                     const BlockBox& extent, EsdfUpdateStats* stats);

  EsdfConfig config_;
  double voxel_size_m_;
  int radius_voxels_ = 0;
  BlockMap blocks_;
  std::uint64_t seen_generation_ = 0;
  float seen_min_weight_ = -1.0f;
  bool full_next_ = true;
  // Scratch of the distance transform, kept between updates.
  std::vector<std::uint8_t> labels_;
  std::vector<std::int16_t> squared_;  // radius_voxels_ <= kEdtMaxRadius16
  EdtScratch edt_scratch_;
};

}  // namespace downstream_perception
