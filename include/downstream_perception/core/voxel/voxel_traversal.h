// Exact 3-D voxel traversal (Amanatides-Woo) of a segment inside a box of voxels.
//
// Coordinates are in voxel units relative to the box's lower corner: voxel (i, j, k) is the
// half-open cube [i, i+1) x [j, j+1) x [k, k+1), so a point exactly on a face belongs to the voxel
// above it (floor), as GridGeometry::worldToCell does in 2-D.
//
// What is visited (the contract the gtest checks against a brute-force slab oracle): the voxel of
// the start point, then every voxel in which the segment spends a positive length, in order, each
// once; the voxel of the end point last (only when include_end). A voxel the segment touches at a
// single point or along an edge line only (a ray through a corner) is not visited: its interior is
// not crossed, and visiting it would clear a voxel on one side of the ray only.
//
// Exactness: the end points are first rounded to 2^-20 voxel (fixed point, int64); everything
// after that is integer arithmetic. Which face is crossed next compares the crossing parameters
// t_a = N_a / d_a of the three axes through their pairwise differences scaled to integers (see
// VoxelWalk::walkWith), and ties (the segment through an edge or a corner) are exact equalities,
// crossed in one diagonal step. No epsilon anywhere: lattice-exact rays (simulated walls, tests)
// are walked exactly like measured ones.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace downstream_perception {

/// GCC/Clang's 128-bit integer (__extension__: not ISO C++, but exact and cheap here).
__extension__ typedef __int128 Int128;

/// A box of voxels [0, nx) x [0, ny) x [0, nz).
struct VoxelBox {
  static constexpr int kMaxVoxelsPerAxis = 1 << 16;
  int nx = 0;
  int ny = 0;
  int nz = 0;
  bool valid() const {
    return nx > 0 && ny > 0 && nz > 0 && nx <= kMaxVoxelsPerAxis && ny <= kMaxVoxelsPerAxis &&
           nz <= kMaxVoxelsPerAxis;
  }
};

struct VoxelIndex {
  int x = 0;
  int y = 0;
  int z = 0;
  bool operator==(const VoxelIndex& o) const { return x == o.x && y == o.y && z == o.z; }
  bool operator!=(const VoxelIndex& o) const { return !(*this == o); }
};

/// A segment in fixed point (units of 2^-20 voxel, box-relative, each coordinate in
/// [0, n * 2^20 - 1]).
struct FixedSegment {
  static constexpr int kShift = 20;
  static constexpr std::int64_t kOne = std::int64_t{1} << kShift;
  std::array<std::int64_t, 3> p0{};
  std::array<std::int64_t, 3> p1{};

  /// A box-relative coordinate u (voxel units) in fixed point, clamped into [0, cells * kOne - 1]
  /// (NaN to 0). Its voxel is the result >> kShift: the voxel a walk ending at u ends in.
  static std::int64_t toFixed(double u, int cells);
};

/// Clips the segment p0-p1 (voxel units, box-relative) to the box and rounds it to fixed point.
/// Returns false when it misses the box or is not finite. *end_clipped tells whether the end was
/// moved (then its voxel is not the measurement's). A moved end lies on the face it was moved to
/// (an upper face: one fixed-point unit inside, the face itself belongs to the voxel beyond).
bool clipToFixed(const VoxelBox& box, const double p0[3], const double p1[3], FixedSegment* out,
                 bool* end_clipped = nullptr);

/// The walk's state; see the file comment.
class VoxelWalk {
 public:
  explicit VoxelWalk(const FixedSegment& s);

  const std::array<int, 3>& start() const { return start_; }
  std::array<int, 3> end() const {
    return {start_[0] + step_[0] * steps_[0], start_[1] + step_[1] * steps_[1],
            start_[2] + step_[2] * steps_[2]};
  }

  /// Calls visit(x, y, z) for each voxel of the segment in order; the end voxel only when
  /// include_end. Returns the number of visits.
  template <class Visitor>
  int walk(bool include_end, Visitor&& visit) const {
    // Rays shorter than 2^30 / 2^20 = 1024 voxels per axis (all sensor rays) in int64, longer
    // ones in __int128: the same arithmetic, the bound is the pairwise terms' magnitude.
    constexpr std::int64_t kShortRay = std::int64_t{1} << 30;
    if (ad_[0] < kShortRay && ad_[1] < kShortRay && ad_[2] < kShortRay) {
      return walkWith<std::int64_t>(include_end, visit);
    }
    return walkWith<Int128>(include_end, visit);
  }

 private:
  // Which face is crossed next compares the crossing parameters t_a = N_a / d_a (N_a: fixed-point
  // distance along axis a to its next face, d_a: the axis' extent). Their pairwise differences,
  // scaled by d_a * d_b, are kept as integers: e_xy = N_x d_y - N_y d_x (< 0: x first, 0: a tie,
  // an edge crossed diagonally), e_xz, e_yz; a step in x adds kOne * d_y to e_xy, and so on.
  // |e| < (d + 2 kOne) * d: below 2^61 for d < 2^30, below 2^108 in __int128 otherwise.
  template <class I, class Visitor>
  int walkWith(bool include_end, Visitor& visit) const {
    constexpr I kOne = FixedSegment::kOne;
    const I ax = ad_[0], ay = ad_[1], az = ad_[2];
    const I fx = first_[0], fy = first_[1], fz = first_[2];
    I exy = fx * ay - fy * ax;
    I exz = fx * az - fz * ax;
    I eyz = fy * az - fz * ay;
    const I kx = kOne * ax, ky = kOne * ay, kz = kOne * az;
    int x = start_[0], y = start_[1], z = start_[2];
    int lx = steps_[0], ly = steps_[1], lz = steps_[2];
    int visits = 0;
    while (lx + ly + lz > 0) {
      visit(x, y, z);
      ++visits;
      // Only axes that still cross a face before the end compete (an axis with no steps left
      // crosses at t >= 1, never before those that do); every earliest one steps.
      const bool cx = lx > 0, cy = ly > 0, cz = lz > 0;
      const bool mx = cx && (!cy || exy <= 0) && (!cz || exz <= 0);
      const bool my = cy && (!cx || exy >= 0) && (!cz || eyz <= 0);
      const bool mz = cz && (!cx || exz >= 0) && (!cy || eyz >= 0);
      if (mx) {
        x += step_[0];
        --lx;
        exy += ky;
        exz += kz;
      }
      if (my) {
        y += step_[1];
        --ly;
        exy -= kx;
        eyz += kz;
      }
      if (mz) {
        z += step_[2];
        --lz;
        exz -= kx;
        eyz -= ky;
      }
    }
    if (include_end) {
      visit(x, y, z);
      ++visits;
    }
    return visits;
  }

  std::array<int, 3> start_{};
  std::array<int, 3> step_{};
  std::array<int, 3> steps_{};
  std::array<std::int64_t, 3> ad_{};     ///< |p1 - p0| per axis, fixed point
  std::array<std::int64_t, 3> first_{};  ///< fixed-point distance to the first face per axis
};

/// Convenience form (tests, Python): the voxels of the segment p0-p1 (voxel units, box-relative),
/// clipped to the box. The end voxel is included when include_end or when the end was clipped.
std::vector<VoxelIndex> voxelRay(const VoxelBox& box, const double p0[3], const double p1[3],
                                 bool include_end = true);

}  // namespace downstream_perception
