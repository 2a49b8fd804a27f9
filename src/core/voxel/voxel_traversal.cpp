#include "downstream_perception/core/voxel/voxel_traversal.h"

#include <algorithm>
#include <cmath>

namespace downstream_perception {

std::int64_t FixedSegment::toFixed(double u, int cells) {
  // Clamped as a double first: casting an out-of-range double to int64 is undefined.
  const double hi = static_cast<double>(std::int64_t{cells} * FixedSegment::kOne - 1);
  const double f = std::round(u * static_cast<double>(FixedSegment::kOne));
  return static_cast<std::int64_t>(std::max(0.0, std::min(f, hi)));
}

bool clipToFixed(const VoxelBox& box, const double p0[3], const double p1[3], FixedSegment* out,
                 bool* end_clipped) {
  if (end_clipped != nullptr) *end_clipped = false;
  if (!box.valid()) return false;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(p0[a]) || !std::isfinite(p1[a])) return false;
  }
  const double size[3] = {static_cast<double>(box.nx), static_cast<double>(box.ny),
                          static_cast<double>(box.nz)};
  // Liang-Barsky against [0, n] per axis.
  double t0 = 0.0;
  double t1 = 1.0;
  int edge0 = -1;  // 2 * axis + (upper ? 1 : 0) of the face an end was moved to
  int edge1 = -1;
  for (int a = 0; a < 3; ++a) {
    const double d = p1[a] - p0[a];
    const double p[2] = {-d, d};
    const double q[2] = {p0[a], size[a] - p0[a]};
    for (int s = 0; s < 2; ++s) {
      if (p[s] == 0.0) {
        if (q[s] < 0.0) return false;
        continue;
      }
      const double t = q[s] / p[s];
      if (p[s] < 0.0) {
        if (t > t1) return false;
        if (t > t0) {
          t0 = t;
          edge0 = 2 * a + s;
        }
      } else {
        if (t < t0) return false;
        if (t < t1) {
          t1 = t;
          edge1 = 2 * a + s;
        }
      }
    }
  }
  const int cells[3] = {box.nx, box.ny, box.nz};
  for (int a = 0; a < 3; ++a) {
    const double d = p1[a] - p0[a];
    out->p0[a] = FixedSegment::toFixed(edge0 >= 0 ? p0[a] + t0 * d : p0[a], cells[a]);
    out->p1[a] = FixedSegment::toFixed(edge1 >= 0 ? p0[a] + t1 * d : p1[a], cells[a]);
  }
  // A moved end is put exactly on its face: p0 + t * d rounds, and at a far end (1e12 voxels)
  // the rounding is larger than a voxel. The clamp in toFixed keeps an upper face inside.
  const auto on_face = [&cells](int edge, std::array<std::int64_t, 3>* p) {
    const int a = edge / 2;
    (*p)[a] = (edge % 2 == 0) ? 0 : std::int64_t{cells[a]} * FixedSegment::kOne - 1;
  };
  if (edge0 >= 0) on_face(edge0, &out->p0);
  if (edge1 >= 0) {
    on_face(edge1, &out->p1);
    if (end_clipped != nullptr) *end_clipped = true;
  }
  return true;
}

VoxelWalk::VoxelWalk(const FixedSegment& s) {
  constexpr std::int64_t kOne = FixedSegment::kOne;
  for (int a = 0; a < 3; ++a) {
    ad_[a] = s.p1[a] >= s.p0[a] ? s.p1[a] - s.p0[a] : s.p0[a] - s.p1[a];
    start_[a] = static_cast<int>(s.p0[a] >> FixedSegment::kShift);
    const int end = static_cast<int>(s.p1[a] >> FixedSegment::kShift);
    step_[a] = s.p1[a] > s.p0[a] ? 1 : -1;
    steps_[a] = std::abs(end - start_[a]);
    first_[a] = step_[a] > 0 ? (std::int64_t{start_[a]} + 1) * kOne - s.p0[a]
                             : s.p0[a] - std::int64_t{start_[a]} * kOne;
  }
}

std::vector<VoxelIndex> voxelRay(const VoxelBox& box, const double p0[3], const double p1[3],
                                 bool include_end) {
  std::vector<VoxelIndex> out;
  FixedSegment s;
  bool end_clipped = false;
  if (!clipToFixed(box, p0, p1, &s, &end_clipped)) return out;
  VoxelWalk(s).walk(include_end || end_clipped, [&out](int x, int y, int z) {
    out.push_back({x, y, z});
  });
  return out;
}

}  // namespace downstream_perception
