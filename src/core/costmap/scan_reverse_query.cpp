// The reverse query of a scan's clearing walk (ClearingWalk::kReverseQuery, issue 20; see the file
// comment of scan_clearing.cpp): the cells a miss could still change ask the rays that can reach
// them, instead of the rays walking every cell.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "scan_walk.h"

namespace downstream_perception {
namespace scan_walk {
namespace {

// ... and while at most one ray in this many starts elsewhere than the scan's common start.
constexpr std::size_t kAutoMaxAsideShare = 8;
// The reverse query's collection of changeable blocks gives up early past this many times its
// budget (the budget counts only the cells the rays reach, known after the collection).
constexpr std::size_t kEarlyDeclineFactor = 4;

// A pseudo-angle of the direction (dx, dy) in [0, 4): monotone in atan2 over a turn starting at
// +x (the "diamond angle"), one division, no trigonometry. Not defined at (0, 0).
inline double pseudoAngle(double dx, double dy) {
  if (dy >= 0) return dx >= 0 ? dy / (dx + dy) : 1.0 - dx / (dy - dx);
  return dx < 0 ? 2.0 - dy / (-dx - dy) : 3.0 + dx / (dx - dy);
}

// The diagonal steps of a walk through lattice corners (its visits are its crossings minus
// those): the corners its walk crosses with two or more crossings left, i.e. the states (a, b)
// with a, b >= 0, a + b <= stepsLeft() - 2 and err + a esx - b esy == tie (see rayClears), the
// solutions of a |dy| - b |dx| = (tie - err) / kOne: one every (|dx|, |dy|) / gcd, counted
// from a particular solution (extended Euclid), in 128 bits; for a ray from a corner, in closed
// form (startsOnCorner: Euclid's 64-bit divisions took most of the reverse query's time on a
// scan from a corner, perf: 3600 beams on 200^2, 2x the time from off the corner).
inline std::int64_t diagonalSteps(const RayWalk& w) {
  if (!w.corners) return 0;
  // |dx|, |dy| < 2^43 (the grid's limits): Euclid's coefficients stay below them, in 64 bits.
  const std::int64_t ady = w.err_step_x >> RayWalk::kShift;
  const std::int64_t adx = w.err_step_y >> RayWalk::kShift;
  const Int128 c = static_cast<Int128>((w.tie - w.err) / RayWalk::kOne);  // exact: corners
  int alpha = 0;
  int beta = 0;
  if (startsOnCorner(w, &alpha, &beta)) {
    // Solutions (a, b) = (k p - beta, k q - alpha), p = |dx| / g, q = |dy| / g; a, b >= 0 and
    // a + b <= stepsLeft() - 2. k = 0 is one when alpha = beta = 0: the start corner itself,
    // entered diagonally.
    const std::int64_t room = static_cast<std::int64_t>(w.stepsLeft()) - 2 + alpha + beta;
    if (room < 0) return 0;
    const std::int64_t at_start = alpha == 0 && beta == 0 ? 1 : 0;
    if (room == 0) return at_start;
    const std::int64_t g = gcdIfAtLeast(adx, ady, (adx + ady + room - 1) / room);
    if (g == 0) return at_start;
    return at_start + room / (adx / g + ady / g);  // k = 1 .. k_max (k_max >= 1 here)
  }
  // s ady + t adx = g
  std::int64_t r0 = ady;
  std::int64_t r1 = adx;
  std::int64_t s0 = 1;
  std::int64_t s1 = 0;
  std::int64_t t0 = 0;
  std::int64_t t1 = 1;
  while (r1 != 0) {
    const std::int64_t q = r0 / r1;
    const std::int64_t r2 = r0 - q * r1;
    r0 = r1;
    r1 = r2;
    const std::int64_t s2 = s0 - q * s1;
    s0 = s1;
    s1 = s2;
    const std::int64_t t2 = t0 - q * t1;
    t0 = t1;
    t1 = t2;
  }
  const std::int64_t g = r0;  // > 0: corners needs both extents
  // |c| < 2^63 / kOne: the remainder and quotient in 64 bits.
  const std::int64_t c64 = static_cast<std::int64_t>(c);
  if (c64 % g != 0) return 0;
  const Int128 a0 = static_cast<Int128>(s0) * (c64 / g);
  const Int128 b0 = -static_cast<Int128>(t0) * (c64 / g);  // ady a0 - adx b0 = c
  const Int128 p = adx / g;
  const Int128 q = ady / g;
  const auto floorDiv = [](Int128 n, Int128 d) { return n / d - ((n % d != 0) && (n < 0)); };
  const auto ceilDiv = [&floorDiv](Int128 n, Int128 d) { return -floorDiv(-n, d); };
  const Int128 k_min = std::max(ceilDiv(-a0, p), ceilDiv(-b0, q));
  const Int128 k_max = floorDiv(static_cast<Int128>(w.stepsLeft()) - 2 - a0 - b0, p + q);
  return k_max < k_min ? 0 : static_cast<std::int64_t>(k_max - k_min + 1);
}

// Whether the walk of `ray` visits cell (x, y) and clears it: a cell before its end cell, or its
// end cell when the ray clears that too. The walk is in cell (a, b) (x and y steps from its start)
// from the later of its a-th x crossing and b-th y crossing to the earlier of its (a+1)-th x and
// (b+1)-th y crossing, and visits it when that is a span, not an instant (a corner crossed
// diagonally touches its two side cells at one point). The (a'+1)-th x crossing comes before
// the (b'+1)-th y crossing exactly when v = err + a' esx - b' esy < tie, at the same point (a
// corner) when v == tie (blockExit's order rule with RayWalk's tie; a ray without corners never
// has v == tie, and for it the rule is the plain one). A corner with one crossing left (at the
// end point) is the end cell's business, decided by the bounds. In 128 bits.
inline bool rayClears(const ClearingRay& ray, int x, int y) {
  const RayWalk& w = ray.walk;
  const int a = (x - w.cx) * w.sx;
  const int b = (y - w.cy) * w.sy;
  if (a < 0 || b < 0 || a > w.steps_x || b > w.steps_y) return false;
  const int n = a + b;
  const int left = w.stepsLeft();
  if (n == left) return ray.clear_end_cell;  // the end cell (a, b both at their ends)
  // Entered through its x edge: the a-th x crossing strictly before the (b+1)-th y crossing.
  if (a > 0 && static_cast<Int128>(w.err) + static_cast<Int128>(a - 1) * w.err_step_x -
                       static_cast<Int128>(b) * w.err_step_y >=
                   w.tie) {
    return false;
  }
  // And the b-th y crossing strictly before the (a+1)-th x crossing.
  if (b > 0 && static_cast<Int128>(w.err) + static_cast<Int128>(a) * w.err_step_x -
                       static_cast<Int128>(b - 1) * w.err_step_y <=
                   w.tie) {
    return false;
  }
  return true;
}

// Whether the 32-cell rows [row, row + rows * size_x) are all saturated free (unflagged, at the
// lower clamp): one compare per eight cells.
inline bool allSaturatedFree(const ScanCells& sc, const std::int16_t* row, int rows) {
#if defined(__SSE2__)
  const __m128i sat = _mm_set1_epi16(sc.saturated_free_raw);
  __m128i all = _mm_set1_epi16(-1);
  for (int y = 0; y < rows; ++y, row += sc.size_x) {
    for (int k = 0; k < kBlock; k += 8) {
      all = _mm_and_si128(
          all, _mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(row + k)), sat));
    }
  }
  return _mm_movemask_epi8(all) == 0xFFFF;
#else
  for (int y = 0; y < rows; ++y, row += sc.size_x) {
    for (int k = 0; k < kBlock; ++k) {
      if (row[k] != sc.saturated_free_raw) return false;
    }
  }
  return true;
#endif
}

// Pass 2 by reverse query (see ClearingWalk::kReverseQuery): adds the cells walked (the rays'
// cells, counted as the per-ray walk counts them) to *walked_out. Returns false, having changed
// nothing, when the box holds more than max_changeable cells a miss could change within the
// rays' reach (a scan over space the grid has not saturated yet: each costs a query, the forward
// walks are cheaper). Cells no ray reaches (unseen space behind the walls, the wedges of beams
// dropped beyond their range) are not counted: they cost the query nothing.
}  // namespace

bool clearByReverseQuery(const ScanCells& sc, const CellBounds& box, int size_y,
                         std::size_t max_changeable, IntegrationScratch* s,
                         std::size_t* walked_out) {
  const int blocks_x = static_cast<int>((sc.size_x + kBlock - 1) >> kBlockShift);
  const std::vector<ClearingRay>& rays = s->rays;
  std::vector<IntegrationScratch::DirectedRay>& dir = s->directed;
  std::vector<ClearingRay>& aside = s->rays_aside;
  dir.clear();
  aside.clear();
  std::size_t walked = 0;
  if (rays.empty()) return true;
  const std::int64_t ox = s->ray_origin[0];
  const std::int64_t oy = s->ray_origin[1];
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const ClearingRay& ray = rays[i];
    if (!s->same_origin[i] || ray.walk.stepsLeft() == 0) {
      aside.push_back(ray);
      continue;
    }
    walked += static_cast<std::size_t>(ray.walk.stepsLeft() - diagonalSteps(ray.walk)) +
              (ray.clear_end_cell ? 1 : 0);
    // The direction in fixed point: err_step_x = kOne |dy|, err_step_y = kOne |dx| (exact).
    const double dx = static_cast<double>(ray.walk.sx * (ray.walk.err_step_y >> RayWalk::kShift));
    const double dy = static_cast<double>(ray.walk.sy * (ray.walk.err_step_x >> RayWalk::kShift));
    const RayWalk& w = ray.walk;
    dir.push_back({pseudoAngle(dx, dy), dx * dx + dy * dy, static_cast<std::uint32_t>(i),
                   std::min(w.cx, w.endX()), std::min(w.cy, w.endY()), std::max(w.cx, w.endX()),
                   std::max(w.cy, w.endY())});
  }
  // Many rays from other starts (a moving sensor's scan) when it may decline (max_changeable below
  // the box's cells: kAuto): the query leaves those to the per-ray walk, the block walk is faster.
  const std::size_t box_cells = static_cast<std::size_t>(box.max_x - box.min_x + 1) *
                                static_cast<std::size_t>(box.max_y - box.min_y + 1);
  if (max_changeable < box_cells && aside.size() * kAutoMaxAsideShare > rays.size()) return false;
  // The blocks of the box with cells a miss could change, and their row masks (bit 0 at the
  // block's first column in the box); the count decides whether the query pays.
  std::vector<IntegrationScratch::QueryBlock>& qblocks = s->query_blocks;
  std::vector<std::uint32_t>& qmasks = s->query_masks;
  qblocks.clear();
  qmasks.clear();
  std::size_t changeable = 0;
  for (int by = box.min_y >> kBlockShift; by <= box.max_y >> kBlockShift; ++by) {
    const int y0 = std::max(box.min_y, by << kBlockShift);
    const int y1 = std::min(box.max_y + 1, (by + 1) << kBlockShift);
    for (int bx = box.min_x >> kBlockShift; bx <= box.max_x >> kBlockShift; ++bx) {
      const int x0 = std::max(box.min_x, bx << kBlockShift);
      const int x1 = std::min(box.max_x + 1, (bx + 1) << kBlockShift);
      // Whole 32-cell rows of the grid where the block fits in it: first a test that every cell
      // is saturated free (most blocks in steady state), then the masks.
      const int xa = bx << kBlockShift;
      const bool whole_rows = xa + kBlock <= sc.size_x;
      if (whole_rows) {
        // Remembered from an earlier scan, or all of the grid's block found saturated now.
        std::uint8_t& known_free = s->block_free[static_cast<std::size_t>(by) * blocks_x + bx];
        if (known_free) continue;
        const int ya = by << kBlockShift;
        const int yb = std::min(size_y, ya + kBlock);
        if (allSaturatedFree(sc, sc.cells + static_cast<std::ptrdiff_t>(ya) * sc.size_x + xa,
                             yb - ya)) {
          known_free = 1;
          continue;
        }
      }
      const std::uint32_t in_box = bitRange(x0 - xa, x1 - 1 - xa);
      const std::size_t offset = qmasks.size();
      std::uint32_t any = 0;
      for (int y = y0; y < y1; ++y) {
        const std::int16_t* row = sc.cells + static_cast<std::ptrdiff_t>(y) * sc.size_x;
        const std::uint32_t m = whole_rows
                                    ? (pendingMask(sc, row + xa, kBlock) & in_box) >> (x0 - xa)
                                    : pendingMask(sc, row + x0, x1 - x0);
        qmasks.push_back(m);
        any |= m;
        changeable += static_cast<std::size_t>(__builtin_popcount(m));
      }
      if (any == 0) {
        qmasks.resize(offset);
        continue;
      }
      std::uint32_t count = 0;
      for (std::size_t k = offset; k < qmasks.size(); ++k) {
        count += static_cast<std::uint32_t>(__builtin_popcount(qmasks[k]));
      }
      qblocks.push_back(
          {x0, y0, x1, y1, static_cast<std::uint32_t>(offset), count, false, {0, 0, 0, 0}});
    }
    // Unreached cells do not count (below), so only far beyond the budget is this already hopeless.
    if (changeable > kEarlyDeclineFactor * max_changeable) return false;
  }
  // By direction: a scan's rays are already in order up to a rotation (one descent, cyclically).
  const std::size_t n = dir.size();
  std::size_t descents = 0;
  std::size_t first = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (dir[i].key > dir[(i + 1) % n].key) {
      ++descents;
      first = (i + 1) % n;
    }
  }
  if (descents <= 1) {
    std::rotate(dir.begin(), dir.begin() + static_cast<std::ptrdiff_t>(first), dir.end());
  } else {
    std::sort(dir.begin(), dir.end(),
              [](const IntegrationScratch::DirectedRay& l,
                 const IntegrationScratch::DirectedRay& r) { return l.key < r.key; });
  }
  const int ocx = static_cast<int>(ox >> RayWalk::kShift);
  const int ocy = static_cast<int>(oy >> RayWalk::kShift);
  constexpr double kEps = 1e-9;
  const std::ptrdiff_t all = static_cast<std::ptrdiff_t>(n);
  // lower_bound over the keys in O(1): a table of the first ray at or after each of kBuckets
  // equal steps of the key, then a short scan (a scan's rays are about as many as the buckets).
  static constexpr int kBuckets = 8192;
  static constexpr double kBucketScale = kBuckets / 4.0;
  std::vector<std::uint32_t>& bucket = s->key_buckets;
  bucket.resize(kBuckets + 1);
  {
    std::size_t i = 0;
    for (int b = 0; b <= kBuckets; ++b) {
      const double start = b / kBucketScale;
      while (i < n && dir[i].key < start) ++i;
      bucket[b] = static_cast<std::uint32_t>(i);
    }
  }
  const auto lowerKey = [&dir, &bucket, n](std::ptrdiff_t from, std::ptrdiff_t to, double k) {
    const int b = std::max(0, std::min(kBuckets, static_cast<int>(k * kBucketScale)));
    std::ptrdiff_t i = std::max<std::ptrdiff_t>(from, bucket[b]);
    (void)n;
    while (i < to && dir[i].key < k) ++i;
    return std::min(i, to);
  };
  // The rays of dir[from, to) whose direction can meet the cells [x0, x1) x [y0, y1) (lattice
  // units), as up to two index ranges r[0..3]; all of dir[from, to) when the rectangle holds or
  // touches the start cell's neighbourhood. A superset: the exact test decides.
  const auto candidates = [&](int cx0, int cy0, int cx1, int cy1, std::ptrdiff_t from,
                              std::ptrdiff_t to, std::ptrdiff_t* r) {
    r[2] = r[3] = 0;
    if (ocx >= cx0 - 1 && ocx <= cx1 && ocy >= cy0 - 1 && ocy <= cy1) {
      r[0] = from;
      r[1] = to;
      return;
    }
    const double x0 = static_cast<double>((static_cast<std::int64_t>(cx0) << RayWalk::kShift) - ox);
    const double y0 = static_cast<double>((static_cast<std::int64_t>(cy0) << RayWalk::kShift) - oy);
    const double x1 = static_cast<double>((static_cast<std::int64_t>(cx1) << RayWalk::kShift) - ox);
    const double y1 = static_cast<double>((static_cast<std::int64_t>(cy1) << RayWalk::kShift) - oy);
    const double k[4] = {pseudoAngle(x0, y0), pseudoAngle(x0, y1), pseudoAngle(x1, y0),
                         pseudoAngle(x1, y1)};
    const double lo = std::min(std::min(k[0], k[1]), std::min(k[2], k[3]));
    const double hi = std::max(std::max(k[0], k[1]), std::max(k[2], k[3]));
    if (hi - lo > 2.0) {     // across the +x axis (pseudo-angle 0 = 4)
      double lo_part = 0.0;  // largest key near 0
      double hi_part = 4.0;  // smallest key near 4
      for (const double kk : k) {
        if (kk < 2.0) lo_part = std::max(lo_part, kk);
        if (kk >= 2.0) hi_part = std::min(hi_part, kk);
      }
      r[0] = from;
      r[1] = lowerKey(from, to, lo_part + kEps);
      r[2] = lowerKey(from, to, hi_part - kEps);
      r[3] = to;
      return;
    }
    r[0] = lowerKey(from, to, lo - kEps);
    r[1] = lowerKey(r[0], to, hi + kEps);
  };
  // The squared distance (fixed point, as a double) from the start to the rectangle.
  const auto distance2 = [&](int cx0, int cy0, int cx1, int cy1) {
    const std::int64_t lx = static_cast<std::int64_t>(cx0) << RayWalk::kShift;
    const std::int64_t hx = static_cast<std::int64_t>(cx1) << RayWalk::kShift;
    const std::int64_t ly = static_cast<std::int64_t>(cy0) << RayWalk::kShift;
    const std::int64_t hy = static_cast<std::int64_t>(cy1) << RayWalk::kShift;
    const double dx = static_cast<double>(ox < lx ? lx - ox : (ox > hx ? ox - hx : 0));
    const double dy = static_cast<double>(oy < ly ? ly - oy : (oy > hy ? oy - hy : 0));
    return dx * dx + dy * dy;
  };
  const auto maxLength2 = [&](const std::ptrdiff_t* r) {
    double m = 0.0;
    for (int part = 0; part < 2; ++part) {
      for (std::ptrdiff_t i = r[2 * part]; i < r[2 * part + 1]; ++i)
        m = std::max(m, dir[i].length2);
    }
    return m;
  };
  // Per block: the rectangle of its changeable cells and its candidate rays; none reaching as far
  // as the rectangle: nothing to clear there. The cells in reach decide whether the query pays;
  // nothing has been written yet, so declining leaves the scan to the block walk.
  std::size_t reachable = 0;
  for (IntegrationScratch::QueryBlock& qb : qblocks) {
    const std::uint32_t* masks = qmasks.data() + qb.masks;
    int ry0 = qb.y1;
    int ry1 = qb.y0;
    std::uint32_t used = 0;
    for (int y = qb.y0; y < qb.y1; ++y) {
      if (masks[y - qb.y0] == 0) continue;
      ry0 = std::min(ry0, y);
      ry1 = y + 1;
      used |= masks[y - qb.y0];
    }
    const int rx0 = qb.x0 + __builtin_ctz(used);
    const int rx1 = qb.x0 + kBlock - __builtin_clz(used);
    candidates(rx0, ry0, rx1, ry1, 0, all, qb.rays);
    qb.reached = n != 0 && maxLength2(qb.rays) * (1.0 + kEps) >= distance2(rx0, ry0, rx1, ry1);
    if (qb.reached) reachable += qb.changeable;
  }
  if (reachable > max_changeable) return false;
  // The other rays first, per ray (any order: each cell takes at most one update per scan; the
  // cells they clear are flagged, and the query below checks each cell's flag again).
  walked += walkRays(aside, sc, Blocks{}, RayWalkKind::kPerRay);
  std::vector<std::uint32_t>& near = s->near_rays;
  for (const IntegrationScratch::QueryBlock& qb : qblocks) {
    if (!qb.reached) continue;
    {
      const int x0 = qb.x0;
      const int y0 = qb.y0;
      const int x1 = qb.x1;
      const int y1 = qb.y1;
      const std::uint32_t* masks = qmasks.data() + qb.masks;
      const std::ptrdiff_t* block_r = qb.rays;
      // The changeable cells in runs along rows, or along columns where those are fewer (the
      // cells behind a wall parallel to y): per run, its candidate rays whose box of cells meets
      // it; none (the common case), nothing in the run can be cleared.
      const int rows = y1 - y0;
      int row_runs = 0;
      for (int y = 0; y < rows; ++y) row_runs += __builtin_popcount(masks[y] & ~(masks[y] << 1));
      std::uint32_t cols[kBlock] = {};
      int col_runs = row_runs;
      if (row_runs > 2) {
        std::copy(masks, masks + rows, cols);
        transpose32(cols);
        col_runs = 0;
        for (int x = 0; x < kBlock; ++x) col_runs += __builtin_popcount(cols[x] & ~(cols[x] << 1));
      }
      const bool by_columns = col_runs < row_runs;
      const int lines = by_columns ? x1 - x0 : rows;
      for (int line = 0; line < lines; ++line) {
        std::uint32_t mask = by_columns ? cols[line] : masks[line];
        while (mask != 0) {
          const int s0 = __builtin_ctz(mask);
          const std::uint32_t rest = ~(mask >> s0);
          const int len = rest == 0 ? 32 - s0 : __builtin_ctz(rest);
          mask = len + s0 >= 32 ? 0 : mask & ~(((1u << len) - 1) << s0);
          // The run's cells [xs, xe) x [ys, ye).
          const int xs = by_columns ? x0 + line : x0 + s0;
          const int xe = by_columns ? xs + 1 : xs + len;
          const int ys = by_columns ? y0 + s0 : y0 + line;
          const int ye = by_columns ? ys + len : ys + 1;
          std::ptrdiff_t r[4];
          if (block_r[2] == block_r[3]) {
            candidates(xs, ys, xe, ye, block_r[0], block_r[1], r);
          } else {
            candidates(xs, ys, xe, ye, 0, all, r);
          }
          near.clear();
          for (int part = 0; part < 2; ++part) {
            for (std::ptrdiff_t i = r[2 * part]; i < r[2 * part + 1]; ++i) {
              const IntegrationScratch::DirectedRay& d = dir[i];
              if (ye <= d.min_y || ys > d.max_y || xe <= d.min_x || xs > d.max_x) continue;
              near.push_back(d.ray);
            }
          }
          if (near.empty()) continue;
          for (int y = ys; y < ye; ++y) {
            std::int16_t* row = sc.cells + static_cast<std::ptrdiff_t>(y) * sc.size_x;
            for (int x = xs; x < xe; ++x) {
              for (const std::uint32_t k : near) {
                if (rayClears(rays[k], x, y)) {
                  if (!sc.skipsMiss(row[x])) sc.clear(row + x);  // unless an other ray's
                  break;
                }
              }
            }
          }
        }
      }
    }
  }
  *walked_out += walked;
  return true;
}

}  // namespace scan_walk
}  // namespace downstream_perception
