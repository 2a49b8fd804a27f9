// Pass 1 and pass 2 of a scan's integration (integrateBeams, see scan_integrator.h): the hits,
// then the clearing walk of every ray, each cell updated at most once per scan.
//
// The clearing walk and the block skip (issue 20). With 3600 beams on a 1000^2 map, rays overlap
// heavily near the sensor: a scan visits ~2.2 M cells, ~2.7 visits per distinct cell, and in a
// steady scene almost every visit finds the cell already saturated free or already updated in this
// scan (skipsMiss), so it does nothing but cost a step. The block walk cuts the grid into
// kBlock x kBlock blocks and keeps, per scan, for each block entered the number of its cells that
// a miss could still change (not flagged, not saturated free): counted when a ray first enters the
// block, decremented whenever the walk clears one of them. In this scan a cell can only go from
// "a miss changes it" to "flagged" (hits are all applied before any clearing; a flagged cell stays
// flagged until the end), so a block whose count reached 0 stays that way, and a ray crosses it in
// one step: where it leaves the block follows from the walk's integer error term exactly (see
// blockExit), so the cells the walk would have visited there are exactly the ones it skips, each a
// no-op. A block that still has such cells is crossed in one jump too when the ray's own cells in
// it miss them (the block's row and column masks, see countPending): rays ending at a wall in front
// of unseen cells, rays passing beside an obstacle's shadow. The walk's order of updates is
// unchanged, so the grid, the statistics and even the order of the flagged list are the same as the
// per-ray walk's, bit for bit (test_scan_clearing checks this against the per-ray walk and a plain
// oracle on random scans and on rooms).
//
// The reverse query (issue 20, ClearingWalk::kReverseQuery; kAuto takes it where it took the
// block walk and the box has few changeable cells, on one thread: it beats the two-thread walk). In
// a steady scene few cells can still change (obstacle shadows, the cells at and behind the walls,
// noise), so instead of walking the rays over the cells, the cells ask the rays: the rays from the
// scan's common start are sorted by direction (a pseudo-angle, no trigonometry), the box is scanned
// for blocks holding a cell a miss could change (blocks found all saturated free are remembered
// across scans while the grid's stamp says nothing else changed it; a hit forgets its block), and
// each run of such cells in a row (or column) takes the rays whose direction can meet it and whose
// box of cells does; for those few the exact visit test (rayClears: the walk's own integer order
// rule, with its corner tie) decides per cell. Rays from another start are walked per ray first.
// Each cell takes the same one miss, so the grid and the statistics are the per-ray walk's bit for
// bit (cells_cleared counts visits: a ray's crossings minus its diagonal corner steps); only the
// order of the flag list differs. It falls back to the block walk when the blocks the rays reach
// hold more than one changeable cell per 4 ray cells (a scene the grid has not saturated yet) or
// more than one ray in 8 starts elsewhere (a moving sensor's scan). 3600-beam room, one thread,
// alternating rounds: 0.38-0.45 ms against the block walk's 0.73-0.80 ms.
//
// Which walk kAuto runs over seen space (at least a quarter of a sample of the rays' cells
// saturated free) is timed, not fixed (WalkChooser, walk_chooser.h): per kind of scan the per-ray
// walk, the first-visit walk, the block walk and the reverse query are each measured, the fastest
// runs, and the others are tried again now and then. The fixed rule below is only the first guess.
//
// Dense scans can share the walk with a helper thread in bands of block rows (walkRaysInBands):
// the same grid and statistics, since each cell takes at most one update per scan whatever the
// order. Measured on the 3600-beam room scan (1000^2, costmap_2d 1.17.3 side by side, one
// process, alternating rounds): the masks took our walk from 1.34-1.44 ms to 1.20-1.23 ms (ray
// cells walked one by one 571 k -> 286 k per scan; costmap_2d's updateBounds 0.80-0.89 ms).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/grid/ray_traversal.h"
#include "downstream_perception/core/parallel/shared_work.h"
#include "scan_walk.h"

namespace downstream_perception {

using namespace scan_walk;  // NOLINT: this file's own internals, shared with the reverse query

namespace {

// Whether a corner ray (RayWalk::corners) may cross a corner diagonally after its first step
// (else the plain two-way loop walks it exactly once past the start). Conservative: true unless
// it starts on a corner with no k >= 1 solution.
inline bool crossesCornerPastStart(const RayWalk& w) {
  int alpha = 0;
  int beta = 0;
  if (!startsOnCorner(w, &alpha, &beta)) return true;
  const std::int64_t room = static_cast<std::int64_t>(w.stepsLeft()) - 2 + alpha + beta;
  if (room <= 0) return false;
  const std::int64_t ady = w.err_step_x >> RayWalk::kShift;
  const std::int64_t adx = w.err_step_y >> RayWalk::kShift;
  return gcdIfAtLeast(adx, ady, (adx + ady + room - 1) / room) != 0;
}

// A ray that may pass exactly through cell corners (lattice-exact points): the walk of
// RayWalk::walk on the cell pointer, crossing a corner diagonally (see RayWalk); clears every
// cell before the end cell and returns the end cell's pointer; *visited counts the cells visited.
// Its own function, so the common loop below stays the plain two-way step.
__attribute__((noinline)) std::int16_t* clearThroughCorners(const RayWalk& walk, std::int16_t* p,
                                                            const ScanCells sc,
                                                            std::size_t* visited) {
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  // The walk's constants and the visit count in locals: the cell stores of clear() could
  // otherwise make the compiler reload them through `walk` and store the count every cell.
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  const std::int64_t tie = walk.tie;
  std::int64_t err = walk.err;
  std::size_t count = 0;
  for (int left = walk.stepsLeft(); left > 0; --left) {
    if (__builtin_expect(!sc.skipsMiss(*p), 0)) sc.clear(p);
    ++count;
    if (err == tie && left >= 2) {  // both edges of the corner in one step
      p += dpx + dpy;
      err += esx - esy;
      --left;
    } else if (err <= 0) {
      p += dpx;
      err += esx;
    } else {
      p += dpy;
      err -= esy;
    }
  }
  *visited += count;
  return p;
}

std::int16_t* clearFromCorner(const RayWalk& walk, std::int16_t* p, const ScanCells sc,
                              std::size_t* walked, bool first_visits);

// Clears every cell of a ray before its end cell and returns the end cell's pointer; the cells
// visited are added to *walked. The walk moves a cell pointer (+-1 along x, +-size_x along y) and
// keeps its state in registers; the rare update (a cell not yet saturated free) leaves the hot
// loop. Out of line (once per ray): its registers are its own. Aligned to a cache line, so the
// loop's placement does not move with whatever the linker puts before it (that alone changed the
// 360-beam benchmark by up to 15 % between builds of the same code).
__attribute__((noinline, aligned(64))) std::int16_t* clearAlong(const RayWalk& walk,
                                                                std::int16_t* p, const ScanCells sc,
                                                                std::size_t* walked) {
  if (__builtin_expect(walk.corners, 0)) return clearFromCorner(walk, p, sc, walked, false);
  // Pointer steps: +-1 along x, +-size_x along y (see RayWalk for why this is a branch).
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  std::int64_t err = walk.err;
  int left = walk.stepsLeft();
  *walked += static_cast<std::size_t>(left);
  for (; left > 0; --left) {
    if (__builtin_expect(!sc.skipsMiss(*p), 0)) sc.clear(p);
    if (err <= 0) {
      p += dpx;
      err += esx;
    } else {
      p += dpy;
      err -= esy;
    }
  }
  return p;
}

// clearAlong for a scan over space the grid has hardly seen (ClearingWalk::kFirstVisit): most
// visits find a cell that still takes a miss, so the miss path is the hot one; it uses
// missFirstVisit and bounds the changes per ray. Same updates and statistics as clearAlong. In
// seen space clearAlong is faster (make bench, 360 beams steady: 0.14-0.17 against 0.17-0.20 ms).
__attribute__((noinline, aligned(64))) std::int16_t* clearAlongFirstVisits(const RayWalk& walk,
                                                                           std::int16_t* p,
                                                                           const ScanCells sc,
                                                                           std::size_t* walked) {
  if (__builtin_expect(walk.corners, 0)) return clearFromCorner(walk, p, sc, walked, true);
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  std::int64_t err = walk.err;
  int left = walk.stepsLeft();
  *walked += static_cast<std::size_t>(left);
  const std::int16_t* first_changed = nullptr;
  const std::int16_t* last_changed = nullptr;
  std::size_t changed = 0;
  for (; left > 0; --left) {
    if (!sc.skipsMiss(*p) && sc.missFirstVisit(p)) {
      if (changed++ == 0) first_changed = p;
      last_changed = p;
    }
    if (err <= 0) {
      p += dpx;
      err += esx;
    } else {
      p += dpy;
      err -= esy;
    }
  }
  sc.addChanged(first_changed, last_changed, changed);
  return p;
}

// A corner ray (RayWalk::corners) for clearAlong / clearAlongFirstVisits. A sensor standing on a
// lattice corner (a robot started at the map's origin) makes every ray of its scan one, and such
// a ray almost never crosses another corner (crossesCornerPastStart): after its first step
// (diagonal when the start corner is crossed so) the plain loop walks it exactly. 360 beams from a
// corner of a 1000^2 grid took 1.8x the time from off the corner in clearThroughCorners. Out of
// line, so the plain loops' code stays as it was (placement-sensitive, see clearAlong).
__attribute__((noinline)) std::int16_t* clearFromCorner(const RayWalk& walk, std::int16_t* p,
                                                        const ScanCells sc, std::size_t* walked,
                                                        bool first_visits) {
  if (crossesCornerPastStart(walk)) return clearThroughCorners(walk, p, sc, walked);
  RayWalk rest = walk;
  rest.corners = false;
  if (walk.err == walk.tie && walk.stepsLeft() >= 2) {
    if (!sc.skipsMiss(*p)) sc.clear(p);  // the same grid and statistics as missFirstVisit
    ++*walked;
    p += walk.sx + walk.sy * sc.size_x;
    rest.err += walk.err_step_x - walk.err_step_y;
    --rest.steps_x;
    --rest.steps_y;
  }
  return first_visits ? clearAlongFirstVisits(rest, p, sc, walked)
                      : clearAlong(rest, p, sc, walked);
}

// The mark walk of ClearingWalk::kMarkSweep: the cells of clearAlong / clearThroughCorners (the
// same steps) set to 1 in `crossed` (the grid's layout, one byte per cell), from index `i`;
// returns the end cell's index. Stores only: nothing waits for a cell's value.
__attribute__((noinline)) std::ptrdiff_t markAlong(const RayWalk& walk, std::ptrdiff_t i,
                                                   std::uint8_t* crossed, std::ptrdiff_t size_x,
                                                   std::size_t* walked) {
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * size_x;
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  std::int64_t err = walk.err;
  int left = walk.stepsLeft();
  if (__builtin_expect(walk.corners, 0)) {
    for (; left > 0; --left) {
      crossed[i] = 1;
      ++*walked;
      if (err == walk.tie && left >= 2) {
        i += dpx + dpy;
        err += esx - esy;
        --left;
      } else if (err <= 0) {
        i += dpx;
        err += esx;
      } else {
        i += dpy;
        err -= esy;
      }
    }
    return i;
  }
  *walked += static_cast<std::size_t>(left);
  for (; left > 0; --left) {
    crossed[i] = 1;
    const bool step_x = err <= 0;
    i += step_x ? dpx : dpy;
    err += step_x ? esx : -esy;
  }
  return i;
}

// The sweep of ClearingWalk::kMarkSweep over `box`: every crossed cell not flagged (hit in this
// scan) and not saturated free takes its miss, unflagged (nothing of this scan visits it again);
// the marks go back to 0. Counts and bounds the cells whose state class changed, in row order.
void sweepCrossed(const ScanCells& sc, std::uint8_t* crossed, const CellBounds& box,
                  std::vector<std::uint8_t>* row_changed) {
  const int w = box.max_x - box.min_x + 1;
  row_changed->resize(static_cast<std::size_t>(w));
  std::uint8_t* ch = row_changed->data();
  // All in int16 so that the row loop vectorises (|value| <= 16383, |miss| <= 16383: the sums
  // fit). A cell the loop does not miss gets its own value back.
  const auto sat = static_cast<std::int16_t>(sc.saturated_free_raw);
  const auto lo = static_cast<std::int16_t>(sc.lo);
  const auto hi = static_cast<std::int16_t>(sc.hi);
  const auto miss_units = static_cast<std::int16_t>(sc.miss_units);
  const auto occ = static_cast<std::int16_t>(sc.occupied_units);
  const auto fre = static_cast<std::int16_t>(sc.free_units);
  for (int y = box.min_y; y <= box.max_y; ++y) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y) * sc.size_x + box.min_x;
    std::uint8_t* m = crossed + row;
    std::int16_t* c = sc.cells + row;
    int changed = 0;
    for (int x = 0; x < w; ++x) {
      // Selects on int16 only (no bool), so that GCC vectorises the loop.
      const std::int16_t raw = c[x];
      const std::int16_t one = 1;
      const std::int16_t zero = 0;
      const auto miss =
          static_cast<std::int16_t>(m[x] & ((raw & 1) ^ 1) & (raw == sat ? zero : one));
      const auto old_v = static_cast<std::int16_t>(raw >> 1);  // exact when miss (raw even)
      auto v = static_cast<std::int16_t>(old_v + miss_units);
      v = v < lo ? lo : v;
      v = v > hi ? hi : v;
      c[x] = miss != 0 ? static_cast<std::int16_t>(v * 2) : raw;
      m[x] = 0;
      const auto class_old =
          static_cast<std::int16_t>((old_v > occ ? one : zero) - (old_v < fre ? one : zero));
      const auto class_new =
          static_cast<std::int16_t>((v > occ ? one : zero) - (v < fre ? one : zero));
      const auto changed_here =
          static_cast<std::int16_t>(miss & (class_old != class_new ? one : zero));
      ch[x] = static_cast<std::uint8_t>(changed_here);
      changed += changed_here;
    }
    if (changed == 0) continue;
    int first = 0;
    while (!ch[first]) ++first;
    int last = w - 1;
    while (!ch[last]) --last;
    sc.stats->cells_changed += static_cast<std::size_t>(changed);
    sc.stats->changed.expand(box.min_x + first, y);
    sc.stats->changed.expand(box.min_x + last, y);
  }
}

// ClearingWalk::kAuto takes the block walk when the rays' cells add up to more than the cells of
// the box they touch. Why that ratio: blocks only saturate where the beams are denser than the
// cells, i.e. within n / (2 pi) cells of the sensor for n beams, and for rays of L cells the
// steps / box ratio is about n L / (2 L)^2 = n / (4 L): above 1 the saturated disc covers most of
// every ray. Scan benchmark, 1000^2: 360 and 1080 beams (ratio 0.22, 0.67) gain nothing or lose
// up to 1.4x (counting the blocks entered costs more than the few skips save); 3600 beams
// (ratio 2.2) gain 1.8x.
// And only where blocks can be skipped at all: on a grid that has not seen this area yet (the
// first scan after start-up, a reset or a resize) no cell is saturated free and counting the
// blocks is pure cost (first scan 1.4x slower than per ray). A sample of the rays' cells decides
// (saturatedRayShare).
constexpr std::size_t kAutoBlockWalkNumerator = 1;
constexpr std::size_t kAutoBlockWalkDenominator = 1;
constexpr double kAutoMinSaturatedShare = 0.25;
constexpr std::size_t kSaturationSampleRays = 64;
constexpr int kSaturationSamplesPerRay = 4;
// kAuto's reverse query gives up (and the block walk runs) when the blocks the rays reach hold more
// than one cell a miss could change per this many ray cells. Since the chooser times the walks
// (walk_chooser.h), this only has to stop hopeless queries; at 1 in 16 (the rule before the
// chooser, measured on one room) it declined where the query was the fastest walk: a sensor off
// the room's centre (1000^2, 3600 beams: 0.97 ms block walk, 0.66 ms query) and a sensor on a
// cell corner (500^2, 1080 beams: 0.58 against 0.51 ms). At 1 in 4 both take the query; the
// sparse scans where the query loses (5x at 360 beams on 1000^2) still decline.
constexpr std::size_t kAutoRayCellsPerChangeableCell = 4;

// Reports the time from start() to its end, per ray cell, to the chooser (on every return path).
class WalkTiming {
 public:
  WalkTiming() = default;
  WalkTiming(const WalkTiming&) = delete;
  WalkTiming& operator=(const WalkTiming&) = delete;
  void start(WalkChooser* chooser, std::size_t ray_cells) {
    chooser_ = chooser;
    ray_cells_ = std::max<std::size_t>(ray_cells, 1);
    start_ = std::chrono::steady_clock::now();
  }
  ~WalkTiming() {
    if (chooser_ == nullptr) return;
    const std::chrono::duration<double, std::nano> took = std::chrono::steady_clock::now() - start_;
    chooser_->report(took.count() / static_cast<double>(ray_cells_));
  }

 private:
  WalkChooser* chooser_ = nullptr;
  std::size_t ray_cells_ = 1;
  std::chrono::steady_clock::time_point start_;
};

// Share of a sample of the rays' cells (up to 64 rays spread over the scan, 4 cells each, at 1/8,
// 3/8, 5/8 and 7/8 of the way to the end cell) that sit at the lower clamp: whether the rays cross
// space the grid has seen. (A sample of their box, as before, misjudged sparse scans: 360 beams on
// 1000^2 cross about a quarter of their box, so its share sat at the threshold whatever the rays
// found, and a sensor on a cell corner took the first-visit walk on every steady scan, 1.8x
// slower.) The points lie within a cell of the ray's line, close enough for a share.
double saturatedRayShare(const ScanCells& sc, const std::vector<ClearingRay>& rays) {
  if (rays.empty()) return 0.0;
  const std::size_t stride = std::max<std::size_t>(1, rays.size() / kSaturationSampleRays);
  int saturated = 0;
  int sampled = 0;
  for (std::size_t i = stride / 2; i < rays.size(); i += stride) {
    const RayWalk& w = rays[i].walk;
    const std::int64_t dx = w.endX() - w.cx;
    const std::int64_t dy = w.endY() - w.cy;
    for (int q = 1; q < 2 * kSaturationSamplesPerRay; q += 2) {
      const std::int64_t x = w.cx + dx * q / (2 * kSaturationSamplesPerRay);
      const std::int64_t y = w.cy + dy * q / (2 * kSaturationSamplesPerRay);
      saturated += (sc.cells[y * sc.size_x + x] & ~1) == (sc.saturated_free_raw & ~1);
      ++sampled;
    }
  }
  return static_cast<double>(saturated) / sampled;
}

}  // namespace

bool autoChoosesMarkSweep(std::size_t ray_cells, std::size_t box_cells,
                          double saturated_free_share) {
  return 2 * ray_cells >= box_cells && saturated_free_share < kAutoMinSaturatedShare;
}

bool autoChoosesBlockWalk(std::size_t ray_cells, std::size_t box_cells,
                          double saturated_free_share) {
  return ray_cells * kAutoBlockWalkDenominator > box_cells * kAutoBlockWalkNumerator &&
         saturated_free_share >= kAutoMinSaturatedShare;
}

namespace {

// Masks per block: kBlock row masks (bit x of row y: cell (x, y) of the block is one a miss
// could still change), then kBlock column masks (bit y of column x: the same cell).
constexpr int kMasksPerBlock = 2 * kBlock;

// The cells of block (bx, by) that a miss could still change, and where they are (masks, see
// kMasksPerBlock). A ray whose cells in the block all miss them can cross the block in one jump
// like a block with none: e.g. the block of a wall, whose changeable cells are the unseen ones
// behind the wall and the wall cells no beam hit in this scan, which rays ending in front of the
// wall never reach; or the rays passing beside an obstacle in the block of its shadow. Both stay
// valid for the rest of the scan: a cell can only stop being changeable (flagged), never become so.
std::int32_t countPending(const ScanCells& sc, int size_y, int bx, int by, std::uint32_t* masks) {
  const int x0 = bx << kBlockShift;
  const int y0 = by << kBlockShift;
  const int w = static_cast<int>(std::min<std::ptrdiff_t>(kBlock, sc.size_x - x0));
  const int h = std::min(kBlock, size_y - y0);
  std::int32_t count = 0;
  for (int y = 0; y < kBlock; ++y) {
    masks[y] = y < h ? pendingMask(sc, sc.cells + (y0 + y) * sc.size_x + x0, w) : 0;
    count += __builtin_popcount(masks[y]);
  }
  if (count > 0) {
    std::copy(masks, masks + kBlock, masks + kBlock);
    transpose32(masks + kBlock);
  }
  return count;
}

// Whether the rectangle of cells between (ax, ay) and (bx, by) (offsets in the block: a monotone
// walk's cells from a to b lie in it) holds none of the block's changeable cells: the OR of the
// masks of its rows (or of its columns, whichever are fewer) has no bit in its column (row) range.
inline bool missesPending(const std::uint32_t* masks, int ax, int ay, int bx, int by) {
  const int x0 = std::min(ax, bx);
  const int x1 = std::max(ax, bx);
  const int y0 = std::min(ay, by);
  const int y1 = std::max(ay, by);
  std::uint32_t any = 0;
  if (y1 - y0 <= x1 - x0) {
    for (int y = y0; y <= y1; ++y) any |= masks[y];
    return (any & bitRange(x0, x1)) == 0;
  }
  for (int x = x0; x <= x1; ++x) any |= masks[kBlock + x];
  return (any & bitRange(y0, y1)) == 0;
}

// Where a walk in state (err) leaves the block it is in, when it needs nx more x steps to cross the
// block's x edge and ny more y steps to cross its y edge: the x and y steps the walk takes up to
// and including the step that leaves (*tx, *ty). The walk steps x while err <= 0; after a x steps
// and b y steps err = err0 + a * esx - b * esy, whatever the order, so the (a+1)-th x crossing
// comes before the (b+1)-th y crossing exactly when err0 + a * esx - b * esy <= 0. Rays with a
// corner (err can equal the tie) are not walked here. The caller bounds |err| and the steps so
// that no product overflows (see clearAlongBlocks).
inline void blockExit(std::int64_t err, std::int64_t esx, std::int64_t esy, int nx, int ny, int* tx,
                      int* ty) {
  const std::int64_t a = nx - 1;
  const std::int64_t b = ny - 1;
  if (err + a * esx - b * esy <= 0) {
    // Leaves through the x edge: nx x steps and the y steps whose crossing comes before the last
    // one, i.e. every b' >= 0 with err + a * esx - b' * esy > 0 (esy > 0 here: a ray with no x
    // extent never steps x).
    const std::int64_t num = err + a * esx;
    *tx = nx;
    *ty = num <= 0 ? 0 : static_cast<int>((num + esy - 1) / esy);
  } else {
    // Leaves through the y edge: ny y steps and every a' >= 0 with err + a' * esx - b * esy <= 0
    // (esx > 0 here: a ray with no y extent never steps y).
    const std::int64_t num = b * esy - err;
    *ty = ny;
    *tx = num < 0 ? 0 : static_cast<int>(num / esx + 1);
  }
}

// The count of block (bx, by)'s changeable cells, counted (with its masks) when the scan first
// enters the block.
inline std::int32_t* blockPending(const ScanCells& sc, const Blocks& blocks, int bx, int by) {
  const std::uint32_t b = static_cast<std::uint32_t>(by) * blocks.blocks_x + bx;
  std::int32_t* pending = blocks.pending + b;
  if (*pending < 0) {
    *pending = countPending(sc, blocks.size_y, bx, by, blocks.masks + b * kMasksPerBlock);
    blocks.checked->push_back(b);
  }
  return pending;
}

// The steps from the walk's cell (state err) to the first cell of the block it enters next, given
// the steps along the crossing axis (*a for an x edge, *b for a y edge; the other is -1): fills in
// the other axis's steps before that crossing (blockExit's order rule, in 128 bits).
inline void enteringSteps(const RayWalk& walk, std::int64_t err, std::int64_t* a, std::int64_t* b) {
  if (*a >= 0) {  // across an x edge: the y steps before the a-th x step
    const Int128 num = static_cast<Int128>(err) + static_cast<Int128>(*a - 1) * walk.err_step_x;
    *b = num <= 0 ? 0 : static_cast<std::int64_t>((num + walk.err_step_y - 1) / walk.err_step_y);
  } else {  // across a y edge: the x steps before the b-th y step
    const Int128 num = static_cast<Int128>(*b - 1) * walk.err_step_y - err;
    *a = num < 0 ? 0 : static_cast<std::int64_t>(num / walk.err_step_x + 1);
  }
}

// From the walk's state (x, y, err, left, p) in a block it leaves in one jump (nx, ny: its x and
// y steps to the block's far edges), follows the blocks the walk enters next, without its cells:
// the nx-th x crossing comes before the ny-th y crossing exactly when err + (nx - 1) esx -
// (ny - 1) esy <= 0 (blockExit's rule), and that sum moves by a block's esx or esy per block, so
// each block costs an add and its pending count (blockExit's division only where a block with
// changeable cells is entered, for the walk's exact state there). Returns false when the ray ends
// in a block with none (the caller goes to the end cell); else the state at the first cell of the
// first block that has some. No overflow: the sum stays within about a block's step of 0 (below
// 2^61 for the block walk's rays), and the exact state is computed in 128 bits.
inline bool crossCleanBlocks(const RayWalk& walk, const ScanCells& sc, const Blocks& blocks, int nx,
                             int ny, int* x, int* y, std::int64_t* err, int* left,
                             std::int16_t** p) {
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  const int end_bx = walk.endX() >> kBlockShift;
  const int end_by = walk.endY() >> kBlockShift;
  int bx = *x >> kBlockShift;
  int by = *y >> kBlockShift;
  std::int64_t next_a = nx;  // x steps from (x, y) to the first cell beyond the next x edge
  std::int64_t next_b = ny;
  std::int64_t order = *err + (next_a - 1) * esx - (next_b - 1) * esy;
  for (;;) {
    std::int64_t a = -1;  // steps from (x, y) to the first cell of the block entered: the one
    std::int64_t b = -1;  // along the crossing axis now, the other one below if needed
    if (order <= 0) {
      a = next_a;
      bx += walk.sx;
      next_a += kBlock;
      order += kBlock * esx;
    } else {
      b = next_b;
      by += walk.sy;
      next_b += kBlock;
      order -= kBlock * esy;
    }
    // Never past the end block (exact arithmetic never gets there; a guard, not a case).
    if ((bx - end_bx) * walk.sx > 0 || (by - end_by) * walk.sy > 0) return false;
    const bool end_block = bx == end_bx && by == end_by;
    // The end block entered at the end cell itself holds none of the walk's cells: not counted.
    // This matters for a band's part of a ray (walkRaysInBands): its end cell is the first cell
    // of its walk in the next band, whose blocks the other thread may be counting and clearing.
    if (end_block) enteringSteps(walk, *err, &a, &b);
    if (end_block && a + b >= *left) return false;
    if (*blockPending(sc, blocks, bx, by) == 0) {
      if (end_block) return false;
      continue;
    }
    if (!end_block) enteringSteps(walk, *err, &a, &b);
    *x += walk.sx * static_cast<int>(a);
    *y += walk.sy * static_cast<int>(b);
    *err = static_cast<std::int64_t>(static_cast<Int128>(*err) + static_cast<Int128>(a) * esx -
                                     static_cast<Int128>(b) * esy);
    *left -= static_cast<int>(a + b);
    *p += a * walk.sx + b * walk.sy * sc.size_x;
    return true;
  }
}

// The walk of clearAlong (no corners) block by block: a block with no pending cell is crossed in
// one jump; in the others every cell is visited, and each cell cleared counts down its block.
// Rays longer than 2^15 cells per axis take clearAlong instead (the caller checks), which keeps
// err and esx, esy below 2^56 and every product in blockExit below 2^62.
__attribute__((noinline, aligned(64))) std::int16_t* clearAlongBlocks(const RayWalk& walk,
                                                                      std::int16_t* p,
                                                                      const ScanCells sc,
                                                                      const Blocks blocks,
                                                                      std::size_t* walked) {
  const std::ptrdiff_t dpx = walk.sx;
  const std::ptrdiff_t dpy = walk.sy * sc.size_x;
  const std::int64_t esx = walk.err_step_x;
  const std::int64_t esy = walk.err_step_y;
  std::int64_t err = walk.err;
  int left = walk.stepsLeft();
  *walked += static_cast<std::size_t>(left);
  int x = walk.cx;
  int y = walk.cy;
  while (left > 0) {
    const int bx = x >> kBlockShift;
    const int by = y >> kBlockShift;
    const std::uint32_t b = static_cast<std::uint32_t>(by) * blocks.blocks_x + bx;
    std::int32_t* const pending = blockPending(sc, blocks, bx, by);
    // Where the walk leaves the block (blockExit: the only place the walk divides).
    const int ox = x & (kBlock - 1);
    const int oy = y & (kBlock - 1);
    const int nx = walk.sx > 0 ? kBlock - ox : ox + 1;
    const int ny = walk.sy > 0 ? kBlock - oy : oy + 1;
    int tx = 0;
    int ty = 0;
    blockExit(err, esx, esy, nx, ny, &tx, &ty);
    const int steps = tx + ty;
    bool jump = *pending == 0;
    if (!jump) {
      // The walk's last cell in this block: the cell before the leaving step, or, if the ray ends
      // here, the cell before its end cell (the end cell is not the walk's: the hit of a return,
      // flagged, or cleared by the caller). The last step is an x step exactly when the last y
      // crossing comes before the last x crossing (the order rule of blockExit).
      int last_x = x + walk.sx * (tx == nx ? tx - 1 : tx);
      int last_y = y + walk.sy * (tx == nx ? ty : ty - 1);
      if (steps >= left) {
        const int rx = (walk.endX() - x) * walk.sx;
        const int ry = (walk.endY() - y) * walk.sy;
        const bool last_step_x =
            ry == 0 ||
            (rx > 0 && err + (rx - 1) * esx - (ry - 1) * static_cast<std::int64_t>(esy) > 0);
        last_x = walk.endX() - (last_step_x ? walk.sx : 0);
        last_y = walk.endY() - (last_step_x ? 0 : walk.sy);
      }
      // Both cells lie in this block (the walk leaves it only with its leaving step).
      jump = missesPending(blocks.masks + b * kMasksPerBlock, ox, oy, last_x & (kBlock - 1),
                           last_y & (kBlock - 1));
    }
    if (jump) {
      // Every cell the walk would visit here is a no-op: cross the block, and every clean block
      // after it, without visiting a cell.
      if (steps >= left ||  // the ray ends in (or just past) this block
          !crossCleanBlocks(walk, sc, blocks, nx, ny, &x, &y, &err, &left, &p)) {
        return sc.cells + static_cast<std::ptrdiff_t>(walk.endY()) * sc.size_x + walk.endX();
      }
      continue;
    }
    // Visit the block's cells cell by cell until the walk leaves the block (its block index
    // along the stepped axis changes) or the ray ends.
    for (;;) {
      if (__builtin_expect(!sc.skipsMiss(*p), 0)) {
        sc.clear(p);
        --*pending;
      }
      --left;
      if (err <= 0) {
        p += dpx;
        err += esx;
        const int from = x;
        x += walk.sx;
        if (left == 0 || (x >> kBlockShift) != (from >> kBlockShift)) break;
      } else {
        p += dpy;
        err -= esy;
        const int from = y;
        y += walk.sy;
        if (left == 0 || (y >> kBlockShift) != (from >> kBlockShift)) break;
      }
    }
  }
  return p;
}

// Walks one clearing ray (pass 2) with the chosen walk; adds the cells walked to *walked.
inline void walkRay(const RayWalk& walk, bool clear_end_cell, const ScanCells& sc,
                    const Blocks& blocks, RayWalkKind kind, std::size_t* walked) {
  // Rays up to 2^15 cells per axis (in the walk's fixed point) take the block walk.
  constexpr std::int64_t kBlockWalkMaxExtent = std::int64_t{1} << (15 + RayWalk::kShift);
  std::int16_t* const start = sc.cells + walk.cy * sc.size_x + walk.cx;
  std::int16_t* p =
      kind == RayWalkKind::kBlocks && !walk.corners &&
              walk.err_step_x < kBlockWalkMaxExtent * RayWalk::kOne &&
              walk.err_step_y < kBlockWalkMaxExtent * RayWalk::kOne
          ? clearAlongBlocks(walk, start, sc, blocks, walked)
          : (kind == RayWalkKind::kFirstVisits ? clearAlongFirstVisits(walk, start, sc, walked)
                                               : clearAlong(walk, start, sc, walked));
  if (clear_end_cell) {
    ++*walked;
    if (!sc.skipsMiss(*p)) sc.clear(p);
  }
}

}  // namespace

std::size_t scan_walk::walkRays(const std::vector<ClearingRay>& rays, const ScanCells& sc,
                                const Blocks& blocks, RayWalkKind kind) {
  std::size_t walked = 0;
  for (const ClearingRay& ray : rays)
    walkRay(ray.walk, ray.clear_end_cell, sc, blocks, kind, &walked);
  return walked;
}

namespace {

// Splits a walk (no corners) where it first enters row `row` (which lies strictly beyond its
// start row and not beyond its end row): *prefix walks the cells before that one (its "end cell"
// is that one, which it does not visit), *suffix starts there with the walk's state at that
// point. The x steps the walk takes before its b-th y step are the a' >= 0 with
// err + a' * esx - (b - 1) * esy <= 0 (see blockExit), in 128 bits: b * esy can pass 2^63.
// Bands of a dense scan's walk shared between two threads: four, so that the claiming evens out
// the band estimate's error (each thread takes about two).
constexpr int kScanBands = 4;

void splitAtRow(const RayWalk& walk, int row, RayWalk* prefix, RayWalk* suffix) {
  const int b = walk.sy > 0 ? row - walk.cy : walk.cy - row;
  // In 64 bits where the numerator fits (every ray of a real map: the 128-bit division is a
  // library call, and each band's walk splits up to two parts per ray), else in 128.
  int a = 0;
  std::int64_t product = 0;
  std::int64_t num64 = 0;
  if (!__builtin_mul_overflow(static_cast<std::int64_t>(b - 1), walk.err_step_y, &product) &&
      !__builtin_sub_overflow(product, walk.err, &num64)) {
    a = num64 < 0 ? 0
                  : static_cast<int>(std::min<std::int64_t>(
                        num64 / walk.err_step_x + 1, static_cast<std::int64_t>(walk.steps_x)));
  } else {
    const Int128 num = static_cast<Int128>(b - 1) * walk.err_step_y - walk.err;
    a = num < 0 ? 0
                : static_cast<int>(std::min<Int128>(num / walk.err_step_x + 1,
                                                    static_cast<Int128>(walk.steps_x)));
  }
  *prefix = walk;
  prefix->steps_x = a;
  prefix->steps_y = b;
  *suffix = walk;
  suffix->cx = walk.cx + walk.sx * a;
  suffix->cy = walk.cy + walk.sy * b;
  suffix->err = walk.err + a * walk.err_step_x - static_cast<std::int64_t>(b) * walk.err_step_y;
  suffix->steps_x = walk.steps_x - a;
  suffix->steps_y = walk.steps_y - b;
}

// Bands of whole block rows holding about equal shares of the rays' cells (each ray's cells spread
// evenly over its rows), so that each block belongs to one band: fills the bands' first rows,
// ascending; fewer bands than asked where the box has too few block rows.
void placeBands(const std::vector<ClearingRay>& rays, const CellBounds& box, int wanted,
                IntegrationScratch* s) {
  const int rows = box.max_y - box.min_y + 1;
  std::vector<double>& work = s->row_work;
  work.assign(static_cast<std::size_t>(rows) + 1, 0.0);
  double total = 0.0;
  for (const ClearingRay& ray : rays) {
    const int y0 = std::min(ray.walk.cy, ray.walk.endY()) - box.min_y;
    const int y1 = std::max(ray.walk.cy, ray.walk.endY()) - box.min_y;
    const double cells = ray.walk.stepsLeft() + 1.0;
    const double per_row = cells / (y1 - y0 + 1);
    work[y0] += per_row;
    work[y1 + 1] -= per_row;
    total += cells;
  }
  s->bands.resize(static_cast<std::size_t>(wanted));
  int count = 0;
  s->bands[count++].first_row = box.min_y;
  double density = 0.0;
  double below = 0.0;
  for (int r = 0; r < rows && count < wanted; ++r) {
    const int y = box.min_y + r;
    // A band edge at the first block boundary where the rows below hold the next share.
    if ((y & (kBlock - 1)) == 0 && y > s->bands[count - 1].first_row &&
        below * wanted >= total * count) {
      s->bands[count++].first_row = y;
    }
    density += work[r];
    below += density;
  }
  s->bands.resize(static_cast<std::size_t>(count));
}

// The band holding row y (bands ascending by first row).
int bandOf(const std::vector<IntegrationScratch::Band>& bands, int y) {
  int band = 0;
  while (band + 1 < static_cast<int>(bands.size()) && y >= bands[band + 1].first_row) ++band;
  return band;
}

// The part of a walk (no corners) in rows [lo, hi) (a band), if it has cells there: from where
// it first enters row lo (or hi - 1, going down) unless it starts inside, to its end or to
// where it first enters the next band's row, which it does not visit (clear_end_cell: the ray's
// own, or false there).
bool partInRows(const ClearingRay& ray, int lo, int hi, RayWalk* part, bool* clear_end_cell) {
  const RayWalk& w = ray.walk;
  const int y0 = w.cy;
  const int y1 = w.endY();
  if (std::max(y0, y1) < lo || std::min(y0, y1) >= hi) return false;
  RayWalk unused = w;
  *part = w;
  if (y0 < lo || y0 >= hi) {  // starts in another band: from its first cell in this one
    splitAtRow(w, w.sy > 0 ? lo : hi - 1, &unused, part);
  }
  *clear_end_cell = ray.clear_end_cell;
  if (y1 < lo || y1 >= hi) {  // ends in another band: up to its first cell in the next one
    const RayWalk from = *part;
    splitAtRow(from, w.sy > 0 ? hi : lo - 1, part, &unused);
    *clear_end_cell = false;
  }
  return true;
}

// Pass 2 in bands shared with the helper thread (see integrateBeams in the header); returns the
// cells walked. Each band's task finds and walks the parts of the rays in its rows itself, so the
// split costs no serial time (it did: 112 of 740 us per 3600-beam scan when the caller split the
// rays into per-band lists). Rays through lattice corners that cross a band edge are walked
// first, on the calling thread: they cannot be split at a row exactly (a corner step changes
// both coordinates). Band results are merged into sc's statistics, flags and checked blocks.
std::size_t walkRaysInBands(const ScanCells& sc, const Blocks& blocks, RayWalkKind kind,
                            const CellBounds& box, int wanted_bands, IntegrationScratch* s) {
  placeBands(s->rays, box, wanted_bands, s);
  std::vector<IntegrationScratch::Band>& bands = s->bands;
  s->rays_serial.clear();
  for (const ClearingRay& ray : s->rays) {
    if (ray.walk.corners && bandOf(bands, ray.walk.cy) != bandOf(bands, ray.walk.endY())) {
      s->rays_serial.push_back(ray);
    }
  }
  std::size_t walked = walkRays(s->rays_serial, sc, blocks, kind);
  const int band_count = static_cast<int>(bands.size());
  runShared(band_count, [&](int i) {
    IntegrationScratch::Band& band = bands[i];
    band.flagged.clear();
    band.blocks_checked.clear();
    band.stats = IntegrationStats();
    band.parts = 0;
    band.walked = 0;
    ScanCells cells = sc;
    cells.flagged = &band.flagged;
    cells.stats = &band.stats;
    Blocks band_blocks = blocks;
    band_blocks.checked = &band.blocks_checked;
    const int lo = band.first_row;
    const int hi = i + 1 < band_count ? bands[i + 1].first_row : box.max_y + 1;
    bool clear_end_cell = false;
    for (const ClearingRay& ray : s->rays) {
      const int y_min = std::min(ray.walk.cy, ray.walk.endY());
      const int y_max = std::max(ray.walk.cy, ray.walk.endY());
      if (y_max < lo || y_min >= hi) continue;
      // A corner ray not wholly in this band is one of the serial ones.
      if (ray.walk.corners && (y_min < lo || y_max >= hi)) continue;
      RayWalk part = ray.walk;
      if (!partInRows(ray, lo, hi, &part, &clear_end_cell)) continue;
      ++band.parts;
      walkRay(part, clear_end_cell, cells, band_blocks, kind, &band.walked);
    }
  });
  for (const auto& band : bands) {
    walked += band.walked;
    sc.stats->cells_changed += band.stats.cells_changed;
    sc.stats->changed.expand(band.stats.changed);
    sc.flagged->insert(sc.flagged->end(), band.flagged.begin(), band.flagged.end());
    blocks.checked->insert(blocks.checked->end(), band.blocks_checked.begin(),
                           band.blocks_checked.end());
  }
  return walked;
}

}  // namespace

IntegrationStats integrateBeams(LogOddsGrid& grid, const std::vector<BeamUpdate>& beams,
                                IntegrationScratch* scratch, ClearingWalk walk_kind, int threads,
                                std::size_t thread_min_cells) {
  IntegrationStats stats;
  const GridGeometry& geometry = grid.geometry();
  if (geometry.cellCount() == 0) return stats;
  IntegrationScratch local_scratch;
  IntegrationScratch& s = scratch != nullptr ? *scratch : local_scratch;
  // Cells flagged in this scan, so the flags can be cleared afterwards (32-bit: the grid is
  // limited to 2^28 cells).
  std::vector<std::uint32_t>& flagged = s.flagged;
  flagged.clear();
  // The per-block memory of saturated blocks holds if nothing changed the grid since the last
  // scan through this scratch (rawCells() below moves the stamp; recorded again on return).
  const bool memory_valid =
      s.stamp_id == grid.stamp().id && s.stamp_version == grid.stamp().version;
  std::int16_t* cells = grid.rawCells();
  struct RecordStamp {
    IntegrationScratch* s;
    const LogOddsGrid* grid;
    ~RecordStamp() {
      s->stamp_id = grid->stamp().id;
      s->stamp_version = grid->stamp().version;
    }
  } record_stamp{&s, &grid};
  const int memory_blocks_x = static_cast<int>((geometry.sizeX() + kBlock - 1) >> kBlockShift);
  const std::size_t memory_blocks =
      static_cast<std::size_t>(memory_blocks_x) *
      static_cast<std::size_t>((geometry.sizeY() + kBlock - 1) >> kBlockShift);
  if (!memory_valid || s.block_free.size() != memory_blocks) s.block_free.assign(memory_blocks, 0);
  const int free_units = grid.freeUnits();
  const int occupied_units = grid.occupiedUnits();
  const ScanCells sc{cells,
                     &flagged,
                     &stats,
                     geometry.sizeX(),
                     grid.clampMinUnits(),
                     grid.clampMaxUnits(),
                     free_units,
                     occupied_units,
                     grid.missUnits(),
                     static_cast<std::int16_t>(grid.clampMinUnits() * 2)};

  // Pass 1: hits. Every hit cell is flagged (even at the clamp) so no beam of this scan clears it.
  const int hit = grid.hitUnits();
  for (const BeamUpdate& beam : beams) {
    if (!beam.mark) continue;
    CellIndex c;
    if (!geometry.worldToCell(beam.hit_x, beam.hit_y, &c)) continue;
    ++stats.beams_marked;
    const std::size_t i = geometry.index(c.x, c.y);
    if (cells[i] & 1) continue;
    ++stats.cells_marked;
    stats.touched.expand(c.x, c.y);
    s.block_free[static_cast<std::size_t>(c.y >> kBlockShift) * memory_blocks_x +
                 (c.x >> kBlockShift)] = 0;
    if (sc.update(i, hit)) {
      ++stats.cells_changed;
      stats.changed.expand(c.x, c.y);
    }
  }

  // Pass 2: pass-throughs, skipping every cell already updated in this scan. The rays are set up
  // first, so that the walk can be chosen from what they are: the block walk pays where the rays
  // cross the box they touch many times over (dense scans), and costs a count of every block
  // entered where they do not (a sparse scan on a large map).
  std::vector<ClearingRay>& rays = s.rays;
  rays.clear();
  s.same_origin.clear();
  bool origin_set = false;
  double origin_x = 0.0;
  double origin_y = 0.0;
  std::size_t steps = 0;
  CellBounds box;
  for (const BeamUpdate& beam : beams) {
    if (!beam.clear) continue;
    double x0 = beam.start_x;
    double y0 = beam.start_y;
    double x1 = beam.end_x;
    double y1 = beam.end_y;
    bool end_clipped = false;
    bool start_clipped = false;
    if (!clipSegmentToGrid(geometry, &x0, &y0, &x1, &y1, &start_clipped, &end_clipped)) continue;
    const RayWalk walk(geometry, x0, y0, x1, y1);
    if (walk_kind == ClearingWalk::kReverseQuery || walk_kind == ClearingWalk::kAuto) {
      // Rays from the same (unclipped) start point share its fixed-point start exactly.
      bool same = false;
      if (!start_clipped) {
        if (!origin_set) {
          origin_set = true;
          origin_x = x0;
          origin_y = y0;
          const double scale = static_cast<double>(RayWalk::kOne) / geometry.resolution();
          s.ray_origin[0] = RayWalk::fixedX(geometry, x0, scale);
          s.ray_origin[1] = RayWalk::fixedY(geometry, y0, scale);
        }
        same = x0 == origin_x && y0 == origin_y;
      }
      s.same_origin.push_back(same ? 1 : 0);
    }
    // The walk stays inside the box of its end cells: bound it per beam, not per cell.
    box.expand(walk.cx, walk.cy);
    box.expand(walk.endX(), walk.endY());
    steps += static_cast<std::size_t>(walk.stepsLeft());
    rays.push_back({walk, beam.clear_end_cell || end_clipped});
  }
  if (!box.empty()) stats.touched.expand(box.min_x, box.min_y);
  if (!box.empty()) stats.touched.expand(box.max_x, box.max_y);
  const std::size_t box_cells = box.empty()
                                    ? 0
                                    : static_cast<std::size_t>(box.max_x - box.min_x + 1) *
                                          static_cast<std::size_t>(box.max_y - box.min_y + 1);
  const double saturated_share =
      walk_kind == ClearingWalk::kAuto && !box.empty() ? saturatedRayShare(sc, rays) : 0.0;
  bool use_blocks = walk_kind == ClearingWalk::kBlockSkip ||
                    (walk_kind == ClearingWalk::kAuto && !box.empty() &&
                     autoChoosesBlockWalk(steps, box_cells, saturated_share));
  const bool mark_sweep = !use_blocks && !box.empty() &&
                          (walk_kind == ClearingWalk::kMarkSweep ||
                           (walk_kind == ClearingWalk::kAuto &&
                            autoChoosesMarkSweep(steps, box_cells, saturated_share)));
  // The first-visit walk over space the grid has hardly seen, where the mark-sweep does not pay
  // (sparse rays: the sweep would cost more than the rays).
  bool first_visits =
      !use_blocks && !mark_sweep && !box.empty() &&
      (walk_kind == ClearingWalk::kFirstVisit ||
       (walk_kind == ClearingWalk::kAuto && saturated_share < kAutoMinSaturatedShare));
  // The reverse query where the block walk would run (dense rays over seen space), unless the box
  // holds too many cells a miss could change (then the block walk runs as before).
  bool try_reverse =
      walk_kind == ClearingWalk::kReverseQuery || (walk_kind == ClearingWalk::kAuto && use_blocks);
  // Over seen space kAuto's rule above is only the prior: the walks give the same grid, so the
  // chooser times them and runs the fastest for this kind of scan (walk_chooser.h).
  // The walk is shared with a second thread where it is large enough (and, over seen space, where
  // the chooser measured that it pays).
  const bool may_share = threads >= 2 && steps >= thread_min_cells && !box.empty() &&
                         box.max_y - box.min_y >= 2 * kBlock;
  bool share = may_share;
  WalkTiming timing;
  if (walk_kind == ClearingWalk::kAuto && !box.empty() && !mark_sweep && !first_visits) {
    const std::uint32_t available =
        may_share ? WalkChooser::kAllWalks : WalkChooser::kOneThreadWalks;
    const WalkChooser::Walk prior = use_blocks  ? WalkChooser::kReverseQuery
                                    : may_share ? WalkChooser::kPerRayShared
                                                : WalkChooser::kPerRay;
    const WalkChooser::Walk chosen =
        s.chooser.choose(WalkChooser::contextOf(steps, box_cells, available), prior, available);
    const WalkChooser::Walk base = WalkChooser::oneThread(chosen);
    use_blocks = base == WalkChooser::kBlocks || base == WalkChooser::kReverseQuery;
    try_reverse = base == WalkChooser::kReverseQuery;
    first_visits = base == WalkChooser::kFirstVisit;
    // The reverse query runs on one thread; its fallback (the block walk) shares as before.
    share = WalkChooser::shared(chosen) || (base == WalkChooser::kReverseQuery && may_share);
    timing.start(&s.chooser, steps);
  }
  if (!box.empty() && try_reverse) {
    std::size_t walked = 0;
    const std::size_t budget = walk_kind == ClearingWalk::kReverseQuery
                                   ? box_cells  // all of them: never falls back
                                   : steps / kAutoRayCellsPerChangeableCell;
    if (clearByReverseQuery(sc, box, static_cast<int>(geometry.sizeY()), budget, &s, &walked)) {
      stats.cells_cleared = walked;
      for (const std::uint32_t i : flagged) cells[i] = static_cast<std::int16_t>(cells[i] & ~1);
      return stats;
    }
  }
  if (mark_sweep) {
    if (s.crossed.size() != geometry.cellCount()) s.crossed.assign(geometry.cellCount(), 0);
    std::size_t walked = 0;
    for (const ClearingRay& ray : rays) {
      const RayWalk& walk = ray.walk;
      const std::ptrdiff_t end =
          markAlong(walk, walk.cy * sc.size_x + walk.cx, s.crossed.data(), sc.size_x, &walked);
      if (ray.clear_end_cell) {
        ++walked;
        s.crossed[end] = 1;
      }
    }
    stats.cells_cleared = walked;
    sweepCrossed(sc, s.crossed.data(), box, &s.row_changed);
    for (const std::uint32_t i : flagged) cells[i] = static_cast<std::int16_t>(cells[i] & ~1);
    return stats;
  }
  if (use_blocks) {
    const int bx = static_cast<int>((geometry.sizeX() + kBlock - 1) >> kBlockShift);
    const int by = static_cast<int>((geometry.sizeY() + kBlock - 1) >> kBlockShift);
    if (bx != s.blocks_x || by != s.blocks_y ||
        s.block_pending.size() != static_cast<std::size_t>(bx) * by) {
      s.blocks_x = bx;
      s.blocks_y = by;
      s.block_pending.assign(static_cast<std::size_t>(bx) * by, -1);
      s.block_masks.assign(static_cast<std::size_t>(bx) * by * kMasksPerBlock, 0);
    }
    s.blocks_checked.clear();
  }
  const int size_y = static_cast<int>(geometry.sizeY());
  const Blocks blocks{s.block_pending.data(), s.block_masks.data(), &s.blocks_checked, s.blocks_x,
                      size_y};
  const RayWalkKind kind = use_blocks     ? RayWalkKind::kBlocks
                           : first_visits ? RayWalkKind::kFirstVisits
                                          : RayWalkKind::kPerRay;
  if (share) {
    stats.cells_cleared = walkRaysInBands(sc, blocks, kind, box, kScanBands, &s);
  } else {
    stats.cells_cleared = walkRays(s.rays, sc, blocks, kind);
  }
  if (use_blocks) {
    for (const std::uint32_t b : s.blocks_checked) s.block_pending[b] = -1;
  }

  for (const std::uint32_t i : flagged) cells[i] = static_cast<std::int16_t>(cells[i] & ~1);
  return stats;
}

}  // namespace downstream_perception
