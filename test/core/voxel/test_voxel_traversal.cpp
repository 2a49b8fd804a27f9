#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "downstream_perception/core/voxel/voxel_traversal.h"

using namespace downstream_perception;  // NOLINT

namespace {

using Key = std::tuple<int, int, int>;
using i128 = Int128;

std::vector<Key> keys(const std::vector<VoxelIndex>& v) {
  std::vector<Key> out;
  for (const auto& c : v) out.emplace_back(c.x, c.y, c.z);
  return out;
}

// A rational a / b with b > 0.
struct Frac {
  i128 num;
  i128 den;
};
bool less(const Frac& a, const Frac& b) {
  return a.num * b.den < b.num * a.den;
}

// The brute-force oracle, exact in integers: voxel (i, j, k) is visited iff the segment (fixed
// point, as the walker sees it) spends a positive length in the half-open cube, or the cube holds
// its start or (with include_end) its end point. Per axis, the parameters t at which the segment
// is inside [lo, hi) form an interval (the slab test); the cube is crossed for a positive length
// iff the largest lower bound is below the smallest upper bound.
std::set<Key> oracle(const FixedSegment& s, bool include_end) {
  const std::int64_t K = FixedSegment::kOne;
  std::set<Key> out;
  int lo_c[3];
  int hi_c[3];
  for (int a = 0; a < 3; ++a) {
    lo_c[a] = static_cast<int>(std::min(s.p0[a], s.p1[a]) / K) - 1;
    hi_c[a] = static_cast<int>(std::max(s.p0[a], s.p1[a]) / K) + 1;
  }
  for (int i = lo_c[0]; i <= hi_c[0]; ++i) {
    for (int j = lo_c[1]; j <= hi_c[1]; ++j) {
      for (int k = lo_c[2]; k <= hi_c[2]; ++k) {
        const int c[3] = {i, j, k};
        Frac lower{0, 1};
        Frac upper{1, 1};
        bool possible = true;
        bool holds_start = true;
        bool holds_end = true;
        for (int a = 0; a < 3; ++a) {
          const i128 lo = i128{c[a]} * K;
          const i128 hi = lo + K;
          const i128 p0 = s.p0[a];
          const i128 d = i128{s.p1[a]} - s.p0[a];
          holds_start = holds_start && lo <= p0 && p0 < hi;
          holds_end = holds_end && lo <= s.p1[a] && s.p1[a] < hi;
          if (d == 0) {
            possible = possible && lo <= p0 && p0 < hi;
            continue;
          }
          const Frac l = d > 0 ? Frac{lo - p0, d} : Frac{p0 - hi, -d};
          const Frac u = d > 0 ? Frac{hi - p0, d} : Frac{p0 - lo, -d};
          if (less(lower, l)) lower = l;
          if (less(u, upper)) upper = u;
        }
        const bool crossed = possible && less(lower, upper);
        if (crossed || holds_start || (include_end && holds_end)) out.emplace(i, j, k);
      }
    }
  }
  return out;
}

void expectMatchesOracle(const VoxelBox& box, const double p0[3], const double p1[3],
                         bool include_end) {
  FixedSegment s;
  bool clipped = false;
  ASSERT_TRUE(clipToFixed(box, p0, p1, &s, &clipped));
  ASSERT_FALSE(clipped);
  std::vector<Key> walked;
  VoxelWalk(s).walk(include_end, [&](int x, int y, int z) { walked.emplace_back(x, y, z); });
  const std::set<Key> unique(walked.begin(), walked.end());
  EXPECT_EQ(unique.size(), walked.size()) << "a voxel was visited twice";
  // A voxel is visited iff the oracle says so (the start voxel is the end voxel when no step is
  // taken: without include_end the walk then visits nothing).
  std::set<Key> expected = oracle(s, include_end);
  if (!include_end && walked.empty()) expected.clear();
  if (!include_end && !walked.empty()) {
    const auto e = VoxelWalk(s).end();
    expected.erase(Key{e[0], e[1], e[2]});  // the end voxel holds the end point: excluded
  }
  EXPECT_EQ(unique, expected) << "(" << p0[0] << ", " << p0[1] << ", " << p0[2] << ") -> (" << p1[0]
                              << ", " << p1[1] << ", " << p1[2] << ")";
  // In order: each step moves every axis by at most one voxel toward the end.
  for (std::size_t n = 1; n < walked.size(); ++n) {
    const auto& [ax, ay, az] = walked[n - 1];
    const auto& [bx, by, bz] = walked[n];
    EXPECT_LE(std::abs(bx - ax) + std::abs(by - ay) + std::abs(bz - az), 3);
    EXPECT_LE(std::abs(bx - ax), 1);
    EXPECT_LE(std::abs(by - ay), 1);
    EXPECT_LE(std::abs(bz - az), 1);
  }
}

}  // namespace

TEST(VoxelTraversal, HandWorkedRays) {
  const VoxelBox box{10, 10, 10};
  {
    // Along x through voxel centres: 3 voxels.
    const double a[3] = {0.5, 0.5, 0.5};
    const double b[3] = {2.5, 0.5, 0.5};
    EXPECT_EQ(keys(voxelRay(box, a, b)), (std::vector<Key>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}));
  }
  {
    // The space diagonal passes through the corners (1,1,1) and (2,2,2): only the three voxels on
    // the diagonal are crossed; the 6 side voxels at each corner are touched at one point.
    const double a[3] = {0.5, 0.5, 0.5};
    const double b[3] = {2.5, 2.5, 2.5};
    EXPECT_EQ(keys(voxelRay(box, a, b)), (std::vector<Key>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}}));
  }
  {
    // y = 0.25 + (x - 0.5) / 2: at x = 1, y = 0.5 (crosses into (1,0)); at x = 2, y = 1 exactly,
    // the corner of (1,0), (2,0), (1,1), (2,1): one diagonal step into (2,1).
    const double a[3] = {0.5, 0.25, 3.5};
    const double b[3] = {2.5, 1.25, 3.5};
    EXPECT_EQ(keys(voxelRay(box, a, b)), (std::vector<Key>{{0, 0, 3}, {1, 0, 3}, {2, 1, 3}}));
  }
  {
    // Start on the face x = 2 moving down in x: the start point is in voxel 2 (floor).
    const double a[3] = {2.0, 0.5, 0.5};
    const double b[3] = {0.5, 0.5, 0.5};
    EXPECT_EQ(keys(voxelRay(box, a, b)), (std::vector<Key>{{2, 0, 0}, {1, 0, 0}, {0, 0, 0}}));
    // Without the end voxel.
    EXPECT_EQ(keys(voxelRay(box, a, b, false)), (std::vector<Key>{{2, 0, 0}, {1, 0, 0}}));
  }
  {
    // End exactly on the face x = 3 moving up: the end point is in voxel 3.
    const double a[3] = {0.5, 0.5, 0.5};
    const double b[3] = {3.0, 0.5, 0.5};
    EXPECT_EQ(keys(voxelRay(box, a, b)).size(), 4u);
    // ... moving down onto the face x = 1: the end is in voxel 1, voxel 0 is not reached.
    const double c[3] = {2.5, 0.5, 0.5};
    const double d[3] = {1.0, 0.5, 0.5};
    EXPECT_EQ(keys(voxelRay(box, c, d)), (std::vector<Key>{{2, 0, 0}, {1, 0, 0}}));
  }
}

TEST(VoxelTraversal, RandomRaysMatchTheSlabOracle) {
  const VoxelBox box{12, 10, 9};
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> ux(0.0, 12.0);
  std::uniform_real_distribution<double> uy(0.0, 10.0);
  std::uniform_real_distribution<double> uz(0.0, 9.0);
  for (int n = 0; n < 2000; ++n) {
    const double a[3] = {ux(rng), uy(rng), uz(rng)};
    const double b[3] = {ux(rng), uy(rng), uz(rng)};
    expectMatchesOracle(box, a, b, n % 2 == 0);
    if (HasFailure()) return;
  }
}

TEST(VoxelTraversal, LatticeExactRaysMatchTheSlabOracle) {
  // End points on a half/quarter-voxel lattice: rays along faces and edges, through corners and
  // edge lines, starting and ending on faces, axis-parallel and zero-length ones.
  const VoxelBox box{8, 8, 8};
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> q(0, 31);  // quarters of a voxel, [0, 7.75]
  int diagonal_steps = 0;
  for (int n = 0; n < 4000; ++n) {
    const double a[3] = {q(rng) / 4.0, q(rng) / 4.0, q(rng) / 4.0};
    double b[3] = {q(rng) / 4.0, q(rng) / 4.0, q(rng) / 4.0};
    if (n % 4 == 1) b[1] = a[1];  // in a plane of constant y (often a face)
    if (n % 4 == 2) b[0] = a[0], b[2] = a[2];
    expectMatchesOracle(box, a, b, n % 3 != 0);
    if (HasFailure()) return;
    const auto cells = voxelRay(box, a, b);
    for (std::size_t k = 1; k < cells.size(); ++k) {
      const int moved = (cells[k].x != cells[k - 1].x) + (cells[k].y != cells[k - 1].y) +
                        (cells[k].z != cells[k - 1].z);
      diagonal_steps += moved > 1;
    }
  }
  EXPECT_GT(diagonal_steps, 100);  // the lattice rays did exercise edge and corner crossings
}

TEST(VoxelTraversal, ClipsToTheBoxAndRefusesNonFinite) {
  const VoxelBox box{5, 5, 5};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const double a[3] = {2.5, 2.5, 2.5};
  const double n[3] = {nan, 1.0, 1.0};
  const double i[3] = {inf, 1.0, 1.0};
  EXPECT_TRUE(voxelRay(box, a, n).empty());
  EXPECT_TRUE(voxelRay(box, i, a).empty());
  // Far outside on both ends, through the box: every voxel inside, ends included.
  const double far0[3] = {-1e12, 2.5, 2.5};
  const double far1[3] = {1e12, 2.5, 2.5};
  EXPECT_EQ(keys(voxelRay(box, far0, far1)),
            (std::vector<Key>{{0, 2, 2}, {1, 2, 2}, {2, 2, 2}, {3, 2, 2}, {4, 2, 2}}));
  // Missing the box entirely.
  const double m0[3] = {-1.0, -1.0, 7.0};
  const double m1[3] = {9.0, 9.0, 7.0};
  EXPECT_TRUE(voxelRay(box, m0, m1).empty());
  // An invalid box.
  EXPECT_TRUE(voxelRay(VoxelBox{0, 5, 5}, a, a).empty());
  // Random far rays: all visited voxels inside, no repeats.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50.0, 55.0);
  for (int k = 0; k < 500; ++k) {
    const double p[3] = {u(rng), u(rng), u(rng)};
    const double q[3] = {u(rng), u(rng), u(rng)};
    const auto cells = voxelRay(box, p, q);
    std::set<Key> seen;
    for (const auto& c : cells) {
      ASSERT_TRUE(c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < 5 && c.y < 5 && c.z < 5);
      ASSERT_TRUE(seen.emplace(c.x, c.y, c.z).second);
    }
  }
}
