// Sparse truncated signed-distance field: voxel blocks of 8^3 in a hash map keyed by block
// index, allocated only where observations put the truncation band.
//
// Voxel i (integer 3-vector) has its centre at i * voxel_size_m in the map frame, so voxel
// centres are the lattice points marching cubes interpolates between. Each voxel holds the
// normalised signed distance D = clamp(sdf / mu, -1, 1) (positive in front of the surface, in
// free space) and the fusion weight W, updated by the weighted running average
// D <- (W D + w d) / (W + w), W <- min(W + w, max_weight) (Curless & Levoy 1996).
#pragma once

#include <tsl/robin_map.h>
#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "downstream_perception/core/tsdf/tsdf_block_pool.h"

namespace downstream_perception {

/// The least depth (voxels along the normal) confirm_depth_max_m caps the confirm depth to: the
/// mesh's crossings need the voxel just behind a surface confirmed, and at 1 voxel the room at
/// 5 cm lost up to 7 % of its surface (docs/tsdf.md).
constexpr double kConfirmDepthFloorVoxels = 1.25;

struct TsdfConfig {
  double voxel_size_m = 0.02;  ///< voxel edge, m; fixed for the map's life
  /// Truncation distance mu in voxels (mu = truncation_voxels * voxel_size_m); 3-5 is usual.
  double truncation_voxels = 4.0;
  /// Cap on the fused weight, so the map keeps following a changing scene (0 = no cap).
  double max_weight = 100.0;
  enum class Weighting {
    kConstant,           ///< w = 1 per observation (Open3D, KinectFusion)
    kInverseSquareDepth  ///< w = 1 / z^2 (z in m): far, noisier depths count less
  };
  Weighting weighting = Weighting::kConstant;  ///< weight of one observation
  /// Behind the surface (sdf < -voxel_size_m) the weight falls linearly to 0 at -mu, so a
  /// surface seen from one side does not write a deep negative shell that ghosts when seen from
  /// the other side (voxblox's weight drop-off). Off by default since issue 22: under pose noise
  /// it loses surface (640x480 / 2 cm, 2 cm / 0.01 rad: completeness 0.56 with it against 0.77
  /// without, ghosts 51 % against 35 %); without pose noise it has fewer of the few ghosts
  /// (0.016 against 0.021 %). docs/tsdf.md has the figures.
  bool behind_surface_dropoff = false;
  /// With behind_surface_dropoff, the weight stays 1 up to this many voxels behind the surface
  /// (sdf = -start * voxel_size_m), then falls linearly to 0 at -mu. 1 = voxblox's ramp (the
  /// default before issue 22); later starts land between that and no ramp (docs/tsdf.md). A value
  /// >= truncation_voxels means no ramp (like behind_surface_dropoff false).
  double behind_surface_dropoff_start_voxels = 1.0;
  /// Depth images: a voxel that frames have only seen deeper than this many voxels behind their
  /// surface (along the surface's normal, where the pixel's incidence is known; at most
  /// confirm_depth_max_m: confirmDepth()) is unconfirmed (TsdfVoxel::weight < 0): its values fuse
  /// (at unconfirmed_update_weight), and the ESDF, the slice and queries read it, but the mesh
  /// leaves it out until some frame sees it nearer a surface or in front of one. Behind a slab
  /// thinner than mu seen only from above (a table top), its deep "inside" values would otherwise
  /// mesh a skirt below the slab's underside where rays beside the slab see free space (issue 22;
  /// docs/tsdf.md). 0 = off (every update confirms).
  double confirm_depth_voxels = 2.5;
  /// Depth images: caps the confirm depth (m along the normal; 0 = no cap), never below
  /// kConfirmDepthFloorVoxels: confirmDepth(). At 5 cm voxels 2.5 voxels is 12.5 cm, three times
  /// a 4 cm table top, and its far side meshed a skirt 6-10 cm under the underside (the accuracy
  /// bench's ghosts at 5 cm); at 2 cm the cap changes nothing (docs/tsdf.md).
  double confirm_depth_max_m = 0.05;
  /// Depth images: an update that does not confirm its voxel (deeper than confirmDepth() behind
  /// its surface) fuses with its weight times this. Such an update only guesses that the object
  /// goes on that deep; under a slab thinner than that, frames looking past the slab see the same
  /// voxels free, and with equal weights the two average to a false "inside" that can mesh a
  /// skirt below the underside. 0.05 clears the room's 4 cm table top at 5 cm voxels (ghosts
  /// 0.07-0.12 % -> 0.00-0.02 %) but, like the drop-off, loses surface under large pose noise
  /// (2 cm / 0.01 rad: completeness 0.83 -> 0.77 at 5 cm, 0.78 -> 0.76 at 2 cm), hence 1 (equal
  /// weights) by default; lower it for well-localised static scenes (docs/tsdf.md). In (0, 1].
  double unconfirmed_update_weight = 1.0;
  /// Depth images: a voxel that some frame saw far free (more than mu in front of its surface)
  /// and that reads free (D > 0) takes a non-confirming update at its weight times this, and an
  /// unconfirmed voxel takes a far-free update at its weight over this. Under a slab thinner
  /// than a voxel (a table top at 5 cm), the voxels below the underside are seen free by frames
  /// looking under the table and guessed "inside" by frames above it; at equal weights the guesses
  /// won, in whichever order they came, and meshed a skirt (5 cm, the room's table top: ghosts
  /// 0.07-0.18 % -> 0.00-0.05 % on the bench's and held-out frames). Unlike
  /// unconfirmed_update_weight it leaves the guesses alone wherever no frame saw the voxel far
  /// free, so surfaces keep their far sides under pose noise (2 cm / 0.01 rad: completeness
  /// 0.826 -> 0.822 at 5 cm, 0.780 -> 0.777 at 2 cm; the lower unconfirmed_update_weight lost
  /// 0.05; docs/tsdf.md). Which voxels were seen far free is one bit per voxel
  /// (TsdfBlock::far_free_rows). 1 = off. In (0, 1].
  double far_free_guess_weight = 0.05;
  /// Depth images: how far behind the surface a pixel next to a depth edge (an object's rim)
  /// writes "inside" values. Rays grazing a rim would otherwise write them into the free space
  /// beyond the object's edges (the projective TSDF's ghost surfaces). A depth edge: neighbouring
  /// pixels more than mu apart in depth (or one invalid) that do not continue one plane (a
  /// surface seen at a grazing angle far away steps by more than mu per pixel without an edge).
  enum class EdgeGuardRule {
    /// Each pixel's depth allowance follows from its distance to the nearest rim and its
    /// incidence angle (depth_rims.h: how far its ray can travel before it may leave the object
    /// through the face behind that rim), times edge_guard_rim_scale (issue 22's defect 4).
    kRimDistance,
    /// Pixels within edge_guard_rad of a rim update at most a voxel behind the surface (more at
    /// grazing incidence: edge_guard_grazing_voxels), the others mu (the rule before issue 22's
    /// defect 4).
    kFixedRadius
  };
  EdgeGuardRule edge_guard_rule = EdgeGuardRule::kRimDistance;
  /// 0 disables the edge guard. kFixedRadius: pixels within this angle (rad) of a depth edge are
  /// guarded. kRimDistance: pixels without an incidence estimate (no neighbour within mu in depth
  /// along a row or a column) within this angle of a rim update a voxel deep, others mu.
  /// 0.0075 rad is 2 pixels at f = 262, 4 at f = 525.
  double edge_guard_rad = 0.0075;
  /// Edge guard: only the nearer side of a depth edge (the object's rim) is a rim, and (with
  /// kFixedRadius) guarded pixels are those at most mu farther than it; the background beside an
  /// object is behind a surface like any other. false: both sides (the guard before issue 22's
  /// defect 4: it cost surface seen only next to objects).
  bool edge_guard_near_side_only = true;
  /// kRimDistance: scales the depth a pixel's distance from the rim allows (1 = the geometric
  /// estimate; larger fills more surface next to rims and lets more ghosts through: 1.25 was a
  /// little more complete on the simulated scenes, but on real PrimeSense frames it raises the
  /// p95 depth residual from 21.8 to 24.0 mm; docs/tsdf.md).
  double edge_guard_rim_scale = 1.0;
  /// kFixedRadius only: a guarded pixel other than the rim pixels themselves still updates
  /// voxels up to voxel_size_m / cos(incidence) behind its surface (incidence: between the ray
  /// and the surface normal estimated from the neighbouring pixels), at most this many voxels.
  /// 1 = a voxel at any incidence.
  double edge_guard_grazing_voxels = 2.0;
  /// Depth images: every pixel writes "inside" values down to this many voxels below its surface
  /// (along the normal: that / cos(incidence) along the ray), even beyond mu, at most
  /// grazing_reach_max_voxels along the ray. At grazing incidence the voxel just under a surface
  /// lies several voxels behind it along the ray, beyond mu: without it a shelf top seen from
  /// just above got no zero crossing on some lattice phases. 0 = off (mu along the ray).
  double grazing_reach_voxels = 1.0;
  /// Cap (voxels along the ray) of grazing_reach_voxels; below truncation_voxels it acts as
  /// truncation_voxels. Bounds the blocks a frame touches behind its surfaces.
  double grazing_reach_max_voxels = 16.0;
  /// Depth images: the incidences (above, and confirm_depth_voxels) are read from the plane of
  /// the (2 r + 1)^2 pixels around each pixel where all of them continue one surface (depths
  /// within two voxels, at most mu, pair by pair), else from a window of half the radius, then of
  /// radius 1, else from the pixel's nearest neighbours. A pixel's own neighbours see depth noise
  /// over a baseline of one pixel: with 5 mm of it the table top's skirt and rim ghosts came back
  /// (640x480, 2 cm: ghosts median 0.056 -> 0.013 %, the worst case 0.38 -> 0.10 %; docs/tsdf.md).
  /// Clean frames mesh as before within 0.0001 of completeness. 0 = off (nearest neighbours only).
  int incidence_window_radius_px = 5;
  /// Depth images: read each voxel's depth by interpolating inverse depth between the four
  /// nearest pixels (exact on planes) instead of taking the nearest pixel; falls back to the
  /// nearest pixel across depth edges (neighbours differing by more than one voxel).
  bool interpolate_depth = true;
  /// Update the voxels along the whole ray from the sensor, not only the truncation band: an
  /// object that moved away is erased where its free space is seen again (voxblox's voxel
  /// carving). Off by default: it allocates blocks for all the free space in view, so memory and
  /// time grow with the range. Carving stays inside the camera's view frustum up to max_depth_m
  /// (PinholeCamera::validate refuses intrinsics whose frustum is absurdly wide or off-axis).
  bool carve_free_space = false;
  /// With carve_free_space, a +Inf pixel ("no return within range", REP 118) carves its ray up to
  /// max_depth_m only in a frame where at least this fraction of all pixels are valid depths:
  /// the returns are the evidence that the sensor works and the pose is right. In other frames
  /// its +Inf pixels are ignored like invalid ones (and counted): one frame without any return
  /// (a covered or failing sensor) would otherwise carve through every wall in view. 0 = +Inf
  /// always carves; 1 = only frames without any invalid or +Inf pixel (so +Inf never carves).
  /// Without carving, +Inf pixels only free voxels of blocks the frame's returns allocate.
  double no_return_carve_min_valid_fraction = 0.5;
  double min_depth_m = 0.1;   ///< closer depths are invalid
  double max_depth_m = 10.0;  ///< farther depths are invalid (at most 1000 m)
  /// Voxels whose weight is below this are "unobserved" for meshing and queries.
  double min_weight = 1e-3;
  /// Marching cubes fills a missing voxel (unobserved, not unconfirmed) next to the surface by
  /// linear extrapolation along a lattice axis from the two observed voxels before it, the
  /// nearer within this many voxels of the surface (and keeping its sign), so the mesh reaches
  /// a surface's edge where the voxel beyond was not written (the edge guard withholds it).
  /// Mesh only: the TSDF, the ESDF, the slice and queries read the observed voxels. 0 = off
  /// (the mesh as before 2026-12: it ends a cube short of such edges); above truncation_voxels
  /// it acts as truncation_voxels; docs/tsdf.md has the measurements.
  double mesh_extrapolate_voxels = 2.0;
  /// Hard cap: new blocks beyond it are not allocated. Lowering it on a live map (setConfig)
  /// evicts blocks down to the new cap at once: the least recently updated first, among equally
  /// recent ones the farthest from the last sensor origin.
  std::size_t max_blocks = 200000;
  /// Blocks whose centre is farther than this from the last sensor origin are evicted after each
  /// integration (0 = never).
  double max_block_distance_m = 0.0;

  double truncation() const { return truncation_voxels * voxel_size_m; }
  /// How deep behind its surface (m along the normal) a depth-image update still confirms its
  /// voxel: confirm_depth_voxels voxels, at most confirm_depth_max_m unless that is less than
  /// kConfirmDepthFloorVoxels voxels (0 when confirm_depth_voxels is 0: off).
  double confirmDepth() const;
  /// Empty if valid, else the reason.
  std::string validate() const;
  /// Settings that differ from their defaults but have no effect, named with the reason; empty
  /// if none. For example edge_guard_grazing_voxels under kRimDistance, the confirm settings
  /// without incidence estimates, mesh_extrapolate_voxels above truncation_voxels (it meshes as
  /// truncation_voxels). The nodelet warns with it.
  std::string inertSettings() const;
};

struct TsdfVoxel {
  float distance = 0.0f;  ///< normalised signed distance D in [-1, 1]
  /// Fused weight; negative while the voxel is unconfirmed (TsdfConfig::confirm_depth_voxels),
  /// its magnitude the weight. The sign keeps the voxel 8 bytes, and readers that test
  /// weight > min_weight (the mesh) leave unconfirmed voxels out without a further check.
  float weight = 0.0f;
  /// The fused weight whether confirmed or not: what the ESDF, the slice and queries read.
  float observedWeight() const { return std::abs(weight); }
};

constexpr int kTsdfBlockSide = 8;
constexpr int kTsdfBlockVoxels = kTsdfBlockSide * kTsdfBlockSide * kTsdfBlockSide;

struct TsdfBlock {
  std::array<TsdfVoxel, kTsdfBlockVoxels> voxels{};
  std::uint64_t updated_stamp = 0;  ///< map generation of the last integration that touched it
  /// Bit x of row linear(0, y, z) / kTsdfBlockSide: some depth frame saw voxel (x, y, z) more
  /// than mu in front of its surface (TsdfConfig::far_free_guess_weight). 64 bytes per 4 KB
  /// block, where a flag in each voxel would have padded it from 8 to 12 bytes.
  std::array<std::uint8_t, kTsdfBlockSide * kTsdfBlockSide> far_free_rows{};
  static int linear(int x, int y, int z) { return x + kTsdfBlockSide * (y + kTsdfBlockSide * z); }
};

struct BlockIndexHash {
  std::size_t operator()(const Eigen::Vector3i& k) const {
    // Large primes (Teschner et al. 2003), the voxel-hashing standard.
    return static_cast<std::size_t>(static_cast<std::int64_t>(k.x()) * 73856093 ^
                                    static_cast<std::int64_t>(k.y()) * 19349669 ^
                                    static_cast<std::int64_t>(k.z()) * 83492791);
  }
};

class TsdfMap {
 public:
  using BlockMap = tsl::robin_map<Eigen::Vector3i, TsdfBlockPool::Ptr, BlockIndexHash>;

  /// Throws std::invalid_argument if the config is invalid.
  explicit TsdfMap(const TsdfConfig& config = {});
  TsdfMap(TsdfMap&&) = default;
  /// Not assignable: the default would free the old pool before the old blocks it holds.
  TsdfMap& operator=(TsdfMap&&) = delete;

  const TsdfConfig& config() const { return config_; }
  /// Replaces the settings that do not define the voxel lattice (weights, depth limits,
  /// edge guard, memory bounds; a lower max_blocks evicts at once, see evictToCap). Empty on
  /// success; else the reason, and nothing changes: an
  /// invalid config, or one with another voxel_size_m or truncation_voxels (those are fixed for
  /// the map's life: the stored distances are in their units).
  std::string setConfig(const TsdfConfig& config);
  double voxelSize() const { return config_.voxel_size_m; }

  /// Voxel indices are kept within +-kMaxVoxelIndex on each axis, so that block indices, block
  /// corners (block * 8) and neighbours (voxel +- 1) are far from int overflow. Points and sensor
  /// origins are accepted only within half of it (inBounds), which leaves room for the band and
  /// the rays around them.
  static constexpr int kMaxVoxelIndex = 1 << 30;
  /// Whether p (m) is finite and within kMaxVoxelIndex / 2 voxels of the origin on every axis
  /// (+-5.4e5 km at 1 cm voxels): the integrators refuse points, and frames whose rays reach,
  /// beyond it (counted as invalid).
  bool inBounds(const Eigen::Vector3d& p) const;

  /// Block containing voxel `voxel`, and the voxel's index inside it (|voxel| <= kMaxVoxelIndex).
  static Eigen::Vector3i blockOf(const Eigen::Vector3i& voxel);
  static int localIndex(const Eigen::Vector3i& voxel);
  /// Nearest voxel to a point (m) that is inBounds(); other points (far, NaN) give an index
  /// clamped to +-kMaxVoxelIndex (NaN: 0), never undefined behaviour: use voxelNear() for them.
  Eigen::Vector3i voxelAt(const Eigen::Vector3d& p) const;
  Eigen::Vector3d voxelCenter(const Eigen::Vector3i& voxel) const {
    return voxel.cast<double>() * config_.voxel_size_m;
  }

  /// The block, created if missing (nullptr when max_blocks is reached); `created`, if given,
  /// says whether this call created it (one hash lookup instead of a find() first).
  TsdfBlock* allocate(const Eigen::Vector3i& block, bool* created = nullptr);
  TsdfBlock* find(const Eigen::Vector3i& block);
  const TsdfBlock* find(const Eigen::Vector3i& block) const;
  /// The voxel if its block exists, else nullptr.
  const TsdfVoxel* voxel(const Eigen::Vector3i& voxel) const;
  /// The voxel nearest p (m) if p is inBounds() and its block exists, else nullptr.
  const TsdfVoxel* voxelNear(const Eigen::Vector3d& p) const;

  /// Voxel v after fusing one observation (normalised distance d, weight w). A plain function
  /// of values, so the integrator's loop over a row of voxels vectorises.
  /// `confirms`: false for an observation deeper than confirm_depth_voxels behind its surface;
  /// the voxel stays (or becomes) unconfirmed unless it was confirmed before.
  TsdfVoxel fused(const TsdfVoxel& v, float d, float w, bool confirms = true) const {
    const float prior = v.observedWeight();
    const float total = prior + w;
    // A zero-weight observation of an unobserved voxel (exactly mu behind the surface with the
    // drop-off) would be 0 / 0: the voxel keeps its value and stays unobserved. Selects only, so
    // the integration loop still vectorises.
    const float average = (prior * v.distance + w * d) / total;
    const float weight = std::min(total, weight_cap_);
    return {total > 0.0f ? average : v.distance, confirms | (v.weight > 0.0f) ? weight : -weight};
  }
  /// Fuses one observation (normalised distance d, weight w) into a voxel.
  void fuse(TsdfVoxel* v, float d, float w) const { *v = fused(*v, d, w); }

  /// Removes blocks whose centre is farther than `distance_m` from `center`; returns how many.
  std::size_t evictFartherThan(const Eigen::Vector3d& center, double distance_m);
  /// Removes blocks beyond max_blocks (the least recently updated first, ties: the farthest
  /// from sensorOrigin()); returns how many. setConfig calls it.
  std::size_t evictToCap();
  /// Blocks evicted by evictToCap over the map's life (a lowered max_blocks).
  std::size_t blocksEvictedToCap() const { return evicted_to_cap_; }
  /// The last sensor origin (map frame) an integration reported; the origin before any.
  const Eigen::Vector3d& sensorOrigin() const { return sensor_origin_; }
  void setSensorOrigin(const Eigen::Vector3d& origin) { sensor_origin_ = origin; }
  void clear();

  const BlockMap& blocks() const { return blocks_; }
  std::size_t blockCount() const { return blocks_.size(); }
  /// Bytes held by the blocks (the pool's whole chunks) and the hash table.
  std::size_t memoryBytes() const;

  /// Incremented by each integration; blocks record the generation that last touched them, so a
  /// mesher can re-extract only blocks changed since its last pass.
  std::uint64_t generation() const { return generation_; }
  std::uint64_t beginIntegration() { return ++generation_; }

 private:
  TsdfConfig config_;
  float weight_cap_ = std::numeric_limits<float>::infinity();  ///< max_weight, or none (0)
  /// Owns the blocks' memory; behind a pointer so moving the map keeps the blocks' deleters
  /// valid, and declared before blocks_ so it outlives them.
  std::unique_ptr<TsdfBlockPool> pool_ = std::make_unique<TsdfBlockPool>();
  BlockMap blocks_;
  std::uint64_t generation_ = 0;
  Eigen::Vector3d sensor_origin_ = Eigen::Vector3d::Zero();
  std::size_t evicted_to_cap_ = 0;
};

}  // namespace downstream_perception
