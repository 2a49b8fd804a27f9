// The pieces of a scan's clearing walk (scan_clearing.cpp) that the reverse query
// (scan_reverse_query.cpp) shares: the cells of one scan's integration, the 32 x 32 blocks and
// their masks, and the arithmetic of rays from lattice corners. Internal to the core library: not
// installed, not part of the API.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/grid/ray_traversal.h"

namespace downstream_perception {
namespace scan_walk {

// The state class of a value in quanta: -1 free, 0 unknown, +1 occupied.
inline int stateClass(int v, int free_units, int occupied_units) {
  return (v > occupied_units) - (v < free_units);
}

// The cells of one scan's integration: applies a delta to an unflagged cell and flags it, and
// the miss of pass 2 with its statistics. Passed by value (a few words) into the out-of-line walk
// below, so that the walk's loop keeps its state in registers: the walks used to be inlined into
// integrateBeams as lambdas capturing its locals by reference, and once a second (corner) walk
// took those lambdas out of line, every cleared cell reloaded the locals through the closures
// (7-13 % more instructions in the scan benchmark).
struct ScanCells {
  std::int16_t* cells;
  std::vector<std::uint32_t>* flagged;
  IntegrationStats* stats;
  std::ptrdiff_t size_x;
  int lo;
  int hi;
  int free_units;
  int occupied_units;
  int miss_units;
  /// Raw (value * 2 + flag) of an unflagged cell sitting at the lower clamp: another miss cannot
  /// change it, so the clearing walk skips it without writing or flagging (the common case in
  /// free space that has been seen before, which is most of every scan).
  std::int16_t saturated_free_raw;

  /// Applies delta to an unflagged cell and flags it; returns whether its state class changed.
  bool update(std::size_t i, int delta) const {
    const int old_v = cells[i] / 2;  // unflagged: raw is even, the division is exact
    const int v = std::min(hi, std::max(lo, old_v + delta));
    cells[i] = static_cast<std::int16_t>(v * 2 + 1);
    flagged->push_back(static_cast<std::uint32_t>(i));
    return stateClass(old_v, free_units, occupied_units) !=
           stateClass(v, free_units, occupied_units);
  }
  /// A cell takes a miss unless it is flagged (hit or cleared in this scan) or already saturated
  /// free: one combined, almost always true test.
  bool skipsMiss(std::int16_t raw) const {
    return static_cast<bool>((raw & 1) | (raw == saturated_free_raw));
  }
  /// The miss of a pass-through cell (not skipped) for the first-visit walk; returns whether its
  /// state class changed. A cell the miss takes to the lower clamp is left unflagged and off the
  /// flagged list: skipsMiss already skips it for the rest of the scan, every hit came before
  /// (pass 1), and a further miss could not change it. (Not in the steady walk: there it measured
  /// slower, see clearAlongFirstVisits.)
  bool missFirstVisit(std::int16_t* p) const {
    const int old_v = *p / 2;  // unflagged: raw is even, the division is exact
    const int v = std::min(hi, std::max(lo, old_v + miss_units));
    if (v == lo) {
      *p = static_cast<std::int16_t>(v * 2);
    } else {
      *p = static_cast<std::int16_t>(v * 2 + 1);
      flagged->push_back(static_cast<std::uint32_t>(p - cells));
    }
    return stateClass(old_v, free_units, occupied_units) !=
           stateClass(v, free_units, occupied_units);
  }
  /// Adds the cells a ray changed between `first` and `last` (both changed) to the statistics: x
  /// and y are monotone along a ray, so the two ends bound them all (two divisions per ray
  /// instead of two per changed cell).
  void addChanged(const std::int16_t* first, const std::int16_t* last, std::size_t count) const {
    if (count == 0) return;
    stats->cells_changed += count;
    for (const std::int16_t* p : {first, last}) {
      const std::size_t i = static_cast<std::size_t>(p - cells);
      stats->changed.expand(static_cast<int>(i % size_x), static_cast<int>(i / size_x));
    }
  }
  /// The miss of a pass-through cell (not skipped).
  void clear(std::int16_t* p) const {
    const std::size_t i = static_cast<std::size_t>(p - cells);
    if (update(i, miss_units)) {
      ++stats->cells_changed;
      stats->changed.expand(static_cast<int>(i % size_x), static_cast<int>(i / size_x));
    }
  }
};

// Blocks of kBlock x kBlock cells (a power of two).
constexpr int kBlockShift = 5;
constexpr int kBlock = 1 << kBlockShift;

__extension__ typedef __int128 Int128;  // GCC/Clang; __extension__: not ISO C++ (-Wpedantic)

// gcd(a, b) if it is at least `floor`, else 0 (a, b > 0). Binary: no division; gcd(a, b) never
// exceeds min(a, b), so the loop stops as soon as that falls below the floor.
inline std::int64_t gcdIfAtLeast(std::int64_t a, std::int64_t b, std::int64_t floor) {
  const int shift = __builtin_ctzll(static_cast<std::uint64_t>(a | b));
  a >>= __builtin_ctzll(static_cast<std::uint64_t>(a));
  while (b != 0) {
    b >>= __builtin_ctzll(static_cast<std::uint64_t>(b));
    if (a > b) std::swap(a, b);
    if ((a << shift) < floor) return 0;
    b -= a;
  }
  return a << shift;
}

// Rays from a sensor standing exactly on a lattice corner (every ray of its scan is then a corner
// ray, RayWalk::corners). The walk crosses a corner diagonally at the states (a, b) (x and y
// steps from the start) with a |dy| - b |dx| = c, c = (tie - err) / kOne. From a corner start c
// is alpha |dx| - beta |dy| with alpha, beta in {0, 1} by the quadrant the ray goes into (the
// first crossing is a whole cell away along an axis it moves up, none along one it moves down),
// so the solutions are (k p - beta, k q - alpha), p = |dx| / g, q = |dy| / g, g = gcd(|dx|, |dy|):
// k = 0 (the start itself, when alpha = beta = 0) and k >= 1 only if p + q fits the crossings left,
// i.e. g >= (|dx| + |dy|) / room; for a measured direction (|dx|, |dy| about 2^20 per cell) that
// is a common factor of about 2^20, which gcdIfAtLeast rules out after a few halvings. Whether
// `w` starts on a corner, and its alpha and beta.
inline bool startsOnCorner(const RayWalk& w, int* alpha, int* beta) {
  const std::int64_t ady = w.err_step_x >> RayWalk::kShift;
  const std::int64_t adx = w.err_step_y >> RayWalk::kShift;
  const std::int64_t c = (w.tie - w.err) / RayWalk::kOne;  // exact for corner rays
  for (*alpha = 0; *alpha < 2; ++*alpha) {
    for (*beta = 0; *beta < 2; ++*beta) {
      if (c == *alpha * adx - *beta * ady) return true;
    }
  }
  return false;
}

// The per-scan block state of the block walk (see the file comment).
struct Blocks {
  std::int32_t* pending;  ///< per block: -1 unchecked, else cells a miss could still change
  std::uint32_t* masks;   ///< per checked block: where those cells are (see countPending)
  std::vector<std::uint32_t>* checked;  ///< blocks whose entry is not -1 (reset after the scan)
  int blocks_x;
  int size_y;
};

// Bit x set: cell x of this block row (w cells) is one a miss could still change.
inline std::uint32_t pendingMask(const ScanCells& sc, const std::int16_t* row, int w) {
#if defined(__SSE2__)
  if (w == kBlock) {
    // 32 cells: four compares of eight int16, packed to bytes, one movemask per 16 cells.
    const __m128i one = _mm_set1_epi16(1);
    const __m128i sat = _mm_set1_epi16(sc.saturated_free_raw);
    std::uint32_t skip = 0;
    for (int half = 0; half < 2; ++half) {
      __m128i flags[2];
      for (int k = 0; k < 2; ++k) {
        const __m128i v =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 16 * half + 8 * k));
        flags[k] =
            _mm_or_si128(_mm_cmpeq_epi16(_mm_and_si128(v, one), one), _mm_cmpeq_epi16(v, sat));
      }
      skip |= static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_packs_epi16(flags[0], flags[1])))
              << (16 * half);
    }
    return ~skip;
  }
#endif
  std::uint32_t mask = 0;
  for (int x = 0; x < w; ++x) mask |= sc.skipsMiss(row[x]) ? 0u : (1u << x);
  return mask;
}

// In place: bit y of a[x] becomes bit x of a[y] (a 32 x 32 bit matrix transpose in five rounds of
// block swaps, Hacker's Delight 7-3, with bit 0 as column 0).
inline void transpose32(std::uint32_t* a) {
  std::uint32_t m = 0x0000FFFFu;
  for (int j = 16; j != 0; j >>= 1, m ^= (m << j)) {
    for (int k = 0; k < 32; k = (k + j + 1) & ~j) {
      const std::uint32_t t = ((a[k] >> j) ^ a[k + j]) & m;
      a[k] ^= t << j;
      a[k + j] ^= t;
    }
  }
}

// Bits lo..hi (0 <= lo <= hi < 32).
inline std::uint32_t bitRange(int lo, int hi) {
  return (0xFFFFFFFFu >> (31 - hi)) & (0xFFFFFFFFu << lo);
}

// The walk a scan's rays take in pass 2 (chosen in integrateBeams).
enum class RayWalkKind { kPerRay, kBlocks, kFirstVisits };

// Walks the clearing rays (pass 2) with the chosen walk; returns the cells walked
// (scan_clearing.cpp).
std::size_t walkRays(const std::vector<ClearingRay>& rays, const ScanCells& sc,
                     const Blocks& blocks, RayWalkKind kind);

// The reverse query (scan_reverse_query.cpp): clears the cells the rays of `s->rays` cross in
// `box` by asking, for each cell a miss could change, the rays that can reach it. Returns false
// (having written nothing) when the blocks the rays reach hold more than `max_changeable` such
// cells (or the rays start at too many points), else adds the cells walked to *walked_out.
bool clearByReverseQuery(const ScanCells& sc, const CellBounds& box, int size_y,
                         std::size_t max_changeable, IntegrationScratch* s,
                         std::size_t* walked_out);

}  // namespace scan_walk
}  // namespace downstream_perception
