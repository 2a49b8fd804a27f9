// The block-skip clearing walk (issue 20) against the per-ray walk and a plain oracle: the same
// grid bit for bit and the same statistics, on random scans over grids whose sizes are not
// multiples of the block, sensors on and off the lattice, rays clipped at the grid's edges and
// repeated scans that saturate the free space (where the skip actually jumps).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/grid/ray_traversal.h"

using namespace downstream_perception;  // NOLINT

namespace {

// Applies a scan's beams the way the file comment of scan_integrator.h says, with no shortcut:
// hits first (once per cell), then every cell of every clearing ray not yet updated in this scan
// takes a miss (clamped). Works on log-odds units, so it is independent of the raw encoding.
void oracleIntegrate(const GridGeometry& g, const LogOddsGrid& like, std::vector<int>* units,
                     const std::vector<BeamUpdate>& beams) {
  std::vector<char> updated(g.cellCount(), 0);
  auto apply = [&](std::size_t i, int delta) {
    (*units)[i] =
        std::min(like.clampMaxUnits(), std::max(like.clampMinUnits(), (*units)[i] + delta));
    updated[i] = 1;
  };
  for (const BeamUpdate& b : beams) {
    if (!b.mark) continue;
    CellIndex c;
    if (!g.worldToCell(b.hit_x, b.hit_y, &c)) continue;
    const std::size_t i = g.index(c.x, c.y);
    if (!updated[i]) apply(i, like.hitUnits());
  }
  for (const BeamUpdate& b : beams) {
    if (!b.clear) continue;
    double x0 = b.start_x, y0 = b.start_y, x1 = b.end_x, y1 = b.end_y;
    bool end_clipped = false;
    if (!clipSegmentToGrid(g, &x0, &y0, &x1, &y1, nullptr, &end_clipped)) continue;
    for (const CellIndex& c : rayCells(g, x0, y0, x1, y1, b.clear_end_cell || end_clipped)) {
      const std::size_t i = g.index(c.x, c.y);
      if (!updated[i]) apply(i, like.missUnits());
    }
  }
}

// A scan of n beams from (sx, sy): returns at random ranges (some beyond the grid, some with no
// return), as the integrator's beams would be after its REP-117 decisions.
std::vector<BeamUpdate> randomScan(std::mt19937* rng, double sx, double sy, int n, double max_r) {
  std::uniform_real_distribution<double> range(0.02, max_r);
  std::uniform_real_distribution<double> jitter(-0.5, 0.5);
  std::uniform_int_distribution<int> kind(0, 9);
  std::vector<BeamUpdate> beams;
  for (int k = 0; k < n; ++k) {
    const double a = 2.0 * M_PI * (k + 0.5 * jitter(*rng)) / n;
    const double r = range(*rng);
    BeamUpdate b;
    b.start_x = sx;
    b.start_y = sy;
    b.end_x = sx + r * std::cos(a);
    b.end_y = sy + r * std::sin(a);
    const int what = kind(*rng);
    b.clear = what != 0;
    b.mark = what >= 3;  // 70 % returns; 20 % no-return or truncated (clear the end cell)
    b.clear_end_cell = what < 3;
    b.hit_x = b.end_x;
    b.hit_y = b.end_y;
    beams.push_back(b);
  }
  return beams;
}

// Each band of the two-thread walk touched only its own rows: the cells it updated (its flagged
// list) and the blocks it counted. Bands run at the same time, so a band reaching into the next
// one's blocks races with it (a ray's part ending at a band edge "ends" in the next band's first
// row; counting that block there rewrote a count the other thread was decrementing).
void expectBandsStayInTheirRows(const IntegrationScratch& s, int size_x) {
  for (std::size_t b = 0; b < s.bands.size(); ++b) {
    const int lo = s.bands[b].first_row;
    const int hi = b + 1 < s.bands.size() ? s.bands[b + 1].first_row : 1 << 30;
    for (const std::uint32_t i : s.bands[b].flagged) {
      const int y = static_cast<int>(i / static_cast<std::uint32_t>(size_x));
      ASSERT_TRUE(y >= lo && y < hi) << "band " << b << " updated row " << y;
    }
    for (const std::uint32_t k : s.bands[b].blocks_checked) {
      const int y0 = static_cast<int>(k / static_cast<std::uint32_t>(s.blocks_x)) * 32;
      ASSERT_TRUE(y0 + 31 >= lo && y0 < hi) << "band " << b << " counted the block at row " << y0;
    }
  }
}

void expectSameStats(const IntegrationStats& a, const IntegrationStats& b) {
  EXPECT_EQ(a.cells_cleared, b.cells_cleared);
  EXPECT_EQ(a.cells_marked, b.cells_marked);
  EXPECT_EQ(a.cells_changed, b.cells_changed);
  EXPECT_EQ(a.beams_marked, b.beams_marked);
  EXPECT_EQ(a.touched.min_x, b.touched.min_x);
  EXPECT_EQ(a.touched.max_x, b.touched.max_x);
  EXPECT_EQ(a.touched.min_y, b.touched.min_y);
  EXPECT_EQ(a.touched.max_y, b.touched.max_y);
  EXPECT_EQ(a.changed.min_x, b.changed.min_x);
  EXPECT_EQ(a.changed.max_x, b.changed.max_x);
  EXPECT_EQ(a.changed.min_y, b.changed.min_y);
  EXPECT_EQ(a.changed.max_y, b.changed.max_y);
}

// Runs `scans` scans from random sensor positions through both walks and the oracle; every
// scan must leave the three grids equal.
void compareWalks(unsigned seed, const GridGeometry& g, int scans, int beams, bool lattice_sensor,
                  const LogOddsConfig& model = {}) {
  std::mt19937 rng(seed);
  LogOddsGrid blocks(g, model);
  LogOddsGrid per_ray(g, model);
  LogOddsGrid automatic(g, model);
  LogOddsGrid threaded(g, model);
  LogOddsGrid threaded_per_ray(g, model);
  LogOddsGrid threaded_first_visit(g, model);
  LogOddsGrid swept(g, model);
  LogOddsGrid first_visit(g, model);
  LogOddsGrid reverse(g, model);
  IntegrationScratch reverse_scratch;
  std::vector<int> oracle(g.cellCount(), 0);
  IntegrationScratch scratch;  // reused across scans, as the integrator does
  IntegrationScratch auto_scratch;
  IntegrationScratch threaded_scratch;
  IntegrationScratch threaded_per_ray_scratch;
  IntegrationScratch threaded_first_visit_scratch;
  IntegrationScratch sweep_scratch;
  const double w = g.sizeX() * g.resolution();
  const double h = g.sizeY() * g.resolution();
  std::uniform_real_distribution<double> ux(g.originX() - 0.1 * w, g.originX() + 1.1 * w);
  std::uniform_real_distribution<double> uy(g.originY() - 0.1 * h, g.originY() + 1.1 * h);
  // Two or three sensor positions visited in turn, so the free space saturates around them.
  std::vector<std::pair<double, double>> sensors;
  for (int s = 0; s < 3; ++s) {
    double x = ux(rng);
    double y = uy(rng);
    if (lattice_sensor) {
      x = g.originX() + std::round((x - g.originX()) / g.resolution()) * g.resolution();
      y = g.originY() + std::round((y - g.originY()) / g.resolution()) * g.resolution();
    }
    sensors.emplace_back(x, y);
  }
  const double max_r = 0.8 * std::max(w, h);
  for (int s = 0; s < scans; ++s) {
    const auto& sensor = sensors[s % sensors.size()];
    const std::vector<BeamUpdate> scan =
        randomScan(&rng, sensor.first, sensor.second, beams, max_r);
    const IntegrationStats a = integrateBeams(blocks, scan, &scratch, ClearingWalk::kBlockSkip);
    const IntegrationStats b = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats c = integrateBeams(automatic, scan, &auto_scratch, ClearingWalk::kAuto);
    // Two threads from the first ray cell on (the default waits for 200,000).
    const IntegrationStats d =
        integrateBeams(threaded, scan, &threaded_scratch, ClearingWalk::kBlockSkip, 2, 0);
    const IntegrationStats e = integrateBeams(threaded_per_ray, scan, &threaded_per_ray_scratch,
                                              ClearingWalk::kPerRay, 2, 0);
    const IntegrationStats f = integrateBeams(
        threaded_first_visit, scan, &threaded_first_visit_scratch, ClearingWalk::kFirstVisit, 2, 0);
    const IntegrationStats g_swept =
        integrateBeams(swept, scan, &sweep_scratch, ClearingWalk::kMarkSweep);
    const IntegrationStats h_first =
        integrateBeams(first_visit, scan, nullptr, ClearingWalk::kFirstVisit);
    const IntegrationStats i_reverse =
        integrateBeams(reverse, scan, &reverse_scratch, ClearingWalk::kReverseQuery);
    const std::vector<int> before = oracle;
    oracleIntegrate(g, per_ray, &oracle, scan);
    // The oracle's statistics: cells whose state class (free / unknown / occupied) changed.
    std::size_t changed = 0;
    CellBounds changed_box;
    const auto cls = [&](int v) {
      return (v > per_ray.occupiedUnits()) - (v < per_ray.freeUnits());
    };
    for (std::size_t i = 0; i < g.cellCount(); ++i) {
      if (cls(before[i]) == cls(oracle[i])) continue;
      ++changed;
      changed_box.expand(static_cast<int>(i % g.sizeX()), static_cast<int>(i / g.sizeX()));
    }
    EXPECT_EQ(b.cells_changed, changed) << "seed " << seed << " scan " << s;
    EXPECT_EQ(b.changed.min_x, changed_box.min_x) << "seed " << seed << " scan " << s;
    EXPECT_EQ(b.changed.max_x, changed_box.max_x) << "seed " << seed << " scan " << s;
    EXPECT_EQ(b.changed.min_y, changed_box.min_y) << "seed " << seed << " scan " << s;
    EXPECT_EQ(b.changed.max_y, changed_box.max_y) << "seed " << seed << " scan " << s;
    expectSameStats(a, b);
    expectSameStats(c, b);
    expectSameStats(d, b);
    expectSameStats(e, b);
    expectSameStats(f, b);
    expectSameStats(g_swept, b);
    expectSameStats(h_first, b);
    expectSameStats(i_reverse, b);
    for (std::size_t i = 0; i < g.cellCount(); ++i) {
      ASSERT_EQ(blocks.rawCells()[i], per_ray.rawCells()[i]) << "seed " << seed << " scan " << s;
      ASSERT_EQ(automatic.rawCells()[i], per_ray.rawCells()[i]) << "seed " << seed << " scan " << s;
      ASSERT_EQ(threaded.rawCells()[i], per_ray.rawCells()[i]) << "seed " << seed << " scan " << s;
      ASSERT_EQ(threaded_per_ray.rawCells()[i], per_ray.rawCells()[i])
          << "seed " << seed << " scan " << s;
      ASSERT_EQ(threaded_first_visit.rawCells()[i], per_ray.rawCells()[i])
          << "seed " << seed << " scan " << s;
      ASSERT_EQ(swept.rawCells()[i], per_ray.rawCells()[i]) << "seed " << seed << " scan " << s;
      ASSERT_EQ(first_visit.rawCells()[i], per_ray.rawCells()[i])
          << "seed " << seed << " scan " << s;
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]) << "seed " << seed << " scan " << s;
      ASSERT_EQ(blocks.units(i), oracle[i]) << "seed " << seed << " scan " << s << " cell " << i;
    }
  }
}

}  // namespace

TEST(ScanClearing, BlockWalkEqualsPerRayAndOracleOnRandomScans) {
  for (unsigned seed = 0; seed < 12; ++seed) {
    std::mt19937 rng(1000 + seed);
    std::uniform_int_distribution<int> size(1, 150);  // mostly not multiples of the 32-cell block
    std::uniform_real_distribution<double> offset(-3.0, 3.0);
    const double res = seed % 3 == 0 ? 0.05 : (seed % 3 == 1 ? 0.1 : 0.037);
    const GridGeometry g(size(rng), size(rng), res, offset(rng), offset(rng));
    compareWalks(seed, g, 25, 300, /*lattice_sensor=*/seed % 2 == 0);
  }
}

TEST(ScanClearing, DenseScansSaturateAndStillMatch) {
  // 3600 beams from one spot over 40 scans: near the sensor every block becomes saturated free
  // (the case the skip is for), while walls keep their hits.
  const GridGeometry g(200, 170, 0.05, -4.3, -4.1);
  compareWalks(77, g, 40, 3600, false);
  compareWalks(78, g, 10, 3600, true);
}

TEST(ScanClearing, SaturatingMissesMatchTheOracle) {
  // A binary-like model (one miss takes a cell to the lower clamp, one hit marks it): the walk
  // leaves such cells unflagged, so later rays of the same scan must still skip them, hits must
  // still win over misses, and the next scan must update them again. Against the oracle, with
  // its statistics, on first scans (all unknown) and on repeated dense ones.
  LogOddsConfig binary;
  binary.p_hit = 0.99;
  binary.p_miss = 0.01;
  binary.clamp_min = -2.1;
  binary.clamp_max = 2.1;
  compareWalks(91, GridGeometry(120, 90, 0.05, -2.9, -2.1), 12, 720, false, binary);
  compareWalks(92, GridGeometry(200, 170, 0.05, -4.3, -4.1), 8, 3600, true, binary);
  // A miss that reaches the clamp only from some values: -0.9 per miss against a clamp of -2.
  LogOddsConfig partial;
  partial.p_miss = 0.29;
  partial.clamp_min = -2.05;
  partial.free_threshold = -1.0;
  compareWalks(93, GridGeometry(90, 110, 0.1, 0.3, -1.7), 20, 500, false, partial);
}

TEST(ScanClearing, AxisAlignedAndSingleCellRays) {
  // Rays with no x or no y extent, and rays inside one cell, through both walks.
  const GridGeometry g(97, 65, 0.1, 0.0, 0.0);
  LogOddsGrid blocks(g);
  LogOddsGrid per_ray(g);
  std::vector<BeamUpdate> scan;
  for (int k = 0; k < 60; ++k) {
    BeamUpdate b;
    b.clear = true;
    b.start_x = 0.05 + 0.1 * (k % 90);
    b.start_y = 3.25;
    b.end_x = k % 3 == 0 ? b.start_x : b.start_x + 0.004;
    b.end_y = k % 2 == 0 ? 0.03 : 6.45;
    scan.push_back(b);
    BeamUpdate c = b;  // horizontal
    c.start_x = 4.85;
    c.start_y = 0.05 + 0.1 * (k % 60);
    c.end_x = k % 2 == 0 ? 0.01 : 9.69;
    c.end_y = c.start_y;
    scan.push_back(c);
    BeamUpdate d = b;  // inside one cell
    d.end_x = d.start_x + 0.01;
    d.end_y = d.start_y + 0.01;
    d.clear_end_cell = k % 2 == 0;
    scan.push_back(d);
  }
  LogOddsGrid reverse(g);
  IntegrationScratch scratch;
  IntegrationScratch reverse_scratch;
  for (int round = 0; round < 12; ++round) {
    const IntegrationStats a = integrateBeams(blocks, scan, &scratch, ClearingWalk::kBlockSkip);
    const IntegrationStats b = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats c =
        integrateBeams(reverse, scan, &reverse_scratch, ClearingWalk::kReverseQuery);
    expectSameStats(a, b);
    expectSameStats(c, b);
    for (std::size_t i = 0; i < g.cellCount(); ++i) {
      ASSERT_EQ(blocks.rawCells()[i], per_ray.rawCells()[i]);
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]);
    }
  }
  // 12 misses at -0.405 each saturate nothing (clamp -8 needs 20): the swept column is free.
  EXPECT_EQ(blocks.state(g.index(0, 30)), CellState::kFree);
}

TEST(ScanClearing, ScratchFollowsAChangeOfGridSize) {
  // One scratch used on a small grid, then a larger one: the block table must be rebuilt.
  IntegrationScratch scratch;
  for (int n : {40, 130, 33}) {
    const GridGeometry g(n, n, 0.1, 0.0, 0.0);
    LogOddsGrid blocks(g);
    LogOddsGrid per_ray(g);
    std::mt19937 rng(static_cast<unsigned>(n));
    for (int s = 0; s < 15; ++s) {
      const auto scan = randomScan(&rng, 0.5 * n * 0.1, 0.5 * n * 0.1, 400, n * 0.1);
      integrateBeams(blocks, scan, &scratch, ClearingWalk::kBlockSkip);
      integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    }
    EXPECT_EQ(scratch.blocks_x, (n + 31) / 32);
    for (std::size_t i = 0; i < g.cellCount(); ++i)
      ASSERT_EQ(blocks.rawCells()[i], per_ray.rawCells()[i]);
  }
}

TEST(ScanClearing, AutoTakesTheBlockWalkOnlyForDenseRaysOverSeenSpace) {
  // Dense rays (twice the box's cells) over a box a quarter or more saturated free: blocks.
  EXPECT_TRUE(autoChoosesBlockWalk(2000, 1000, 0.25));
  EXPECT_TRUE(autoChoosesBlockWalk(2000, 1000, 1.0));
  // The same rays on a grid that has not seen the area (a first scan): per ray.
  EXPECT_FALSE(autoChoosesBlockWalk(2000, 1000, 0.0));
  EXPECT_FALSE(autoChoosesBlockWalk(2000, 1000, 0.24));
  // Sparse rays (fewer cells than the box): per ray, saturated or not.
  EXPECT_FALSE(autoChoosesBlockWalk(1000, 1000, 1.0));
  EXPECT_FALSE(autoChoosesBlockWalk(10, 1000, 1.0));
}

TEST(ScanClearing, AutoTimesEachSteadyWalkAndStaysEqualToThePerRayWalk) {
  // kAuto's chooser (walk_chooser.h) measures each steady walk on its first scans of a kind
  // (the four one-thread walks; with two threads allowed, the three shared ones too), whatever
  // the clock says; every scan must still equal the per-ray walk.
  // A steady scene (no hits within 1.8 m, misses that saturate at once): the chooser's regime.
  const GridGeometry g(200, 170, 0.05, -4.3, -4.1);
  LogOddsConfig model;
  model.p_hit = 0.99;
  model.p_miss = 0.01;
  model.clamp_min = -2.1;
  model.clamp_max = 2.1;
  LogOddsGrid per_ray(g, model);
  LogOddsGrid one_thread(g, model);
  LogOddsGrid two_threads(g, model);
  IntegrationScratch one_scratch;
  IntegrationScratch two_scratch;
  std::mt19937 rng(5);
  for (int s = 0; s < 30; ++s) {
    std::vector<BeamUpdate> scan = randomScan(&rng, 0.013, -0.021, 3600, 2.5);
    for (BeamUpdate& b : scan) {
      if (std::hypot(b.end_x - b.start_x, b.end_y - b.start_y) < 1.8) b.mark = false;
    }
    const IntegrationStats a = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats b = integrateBeams(one_thread, scan, &one_scratch, ClearingWalk::kAuto);
    const IntegrationStats c =
        integrateBeams(two_threads, scan, &two_scratch, ClearingWalk::kAuto, 2, 0);
    expectSameStats(b, a);
    expectSameStats(c, a);
    for (std::size_t i = 0; i < g.cellCount(); ++i) {
      ASSERT_EQ(one_thread.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
      ASSERT_EQ(two_threads.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
    }
  }
  for (int w = 0; w < WalkChooser::kWalks; ++w) {
    const bool shared = WalkChooser::shared(static_cast<WalkChooser::Walk>(w));
    EXPECT_EQ(one_scratch.chooser.runs()[w] >= 2, !shared) << w;
    EXPECT_GE(two_scratch.chooser.runs()[w], 2u) << w;
  }
}

TEST(ScanClearing, TwoThreadsSplitTheRaysAtABlockRow) {
  // A dense scan from the middle of a 200 x 170 grid: rays going up and down, many crossing the
  // split row; the two-thread walk must really split them (else the comparisons above would
  // only compare one thread with itself) and still give the one-thread grid.
  const GridGeometry g(200, 170, 0.05, -5.0, -4.2);
  std::mt19937 rng(5);
  LogOddsGrid one(g);
  LogOddsGrid two(g);
  IntegrationScratch one_scratch;
  IntegrationScratch two_scratch;
  for (int s = 0; s < 8; ++s) {
    const auto scan = randomScan(&rng, 0.013 + 0.2 * s, -0.31, 3600, 9.0);
    // The block walk (kAuto takes the single-threaded mark-sweep for a first dense scan).
    const IntegrationStats a = integrateBeams(one, scan, &one_scratch, ClearingWalk::kBlockSkip, 1);
    const IntegrationStats b =
        integrateBeams(two, scan, &two_scratch, ClearingWalk::kBlockSkip, 2, 0);
    expectSameStats(a, b);
    expectBandsStayInTheirRows(two_scratch, g.sizeX());
    ASSERT_GE(two_scratch.bands.size(), 3u);
    std::size_t parts = 0;
    for (std::size_t b = 0; b < two_scratch.bands.size(); ++b) {
      EXPECT_GT(two_scratch.bands[b].parts, 0u);
      if (b > 0) {
        EXPECT_EQ(two_scratch.bands[b].first_row % 32, 0);  // edges on block boundaries
      }
      parts += two_scratch.bands[b].parts;
    }
    // Split rays appear in several bands: more parts than rays.
    EXPECT_GT(parts + two_scratch.rays_serial.size(), two_scratch.rays.size());
    for (std::size_t i = 0; i < g.cellCount(); ++i) ASSERT_EQ(one.rawCells()[i], two.rawCells()[i]);
  }
  // Below the threshold (the default, 200,000 cells) one thread walks: no bands are placed.
  std::mt19937 rng2(6);
  const auto sparse = randomScan(&rng2, 0.0, 0.0, 100, 9.0);
  two_scratch.bands.clear();
  integrateBeams(two, sparse, &two_scratch, ClearingWalk::kAuto, 2);
  EXPECT_TRUE(two_scratch.bands.empty());
}

TEST(ScanClearing, RaysEndingInFrontOfUnseenCellsMatchThePerRayWalk) {
  // A square room whose outside no ray reaches, from several spots, on and off the lattice: the
  // wall blocks keep unseen (changeable) cells behind the wall, so the block walk decides per ray
  // from the block's masks whether it may jump (its cells miss them) or must walk. Every scan,
  // one thread and two, must match the per-ray walk.
  const GridGeometry g(230, 190, 0.05, -5.6, -4.7);
  const double half_x = 4.4;
  const double half_y = 3.6;
  LogOddsGrid per_ray(g);
  LogOddsGrid blocks(g);
  LogOddsGrid threaded(g);
  LogOddsGrid reverse(g);
  IntegrationScratch block_scratch;
  IntegrationScratch threaded_scratch;
  IntegrationScratch reverse_scratch;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> spot(-1.5, 1.5);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int s = 0; s < 36; ++s) {
    const double sx = s % 4 == 0 ? 0.0 : spot(rng);
    const double sy = s % 4 == 0 ? 0.05 * (s % 3) : spot(rng);
    std::vector<BeamUpdate> scan;
    for (int k = 0; k < 2400; ++k) {
      const double a = 2.0 * M_PI * k / 2400.0;
      const double c = std::cos(a);
      const double d = std::sin(a);
      double r = std::min(c != 0.0 ? (c > 0 ? half_x - sx : half_x + sx) / std::abs(c) : 1e9,
                          d != 0.0 ? (d > 0 ? half_y - sy : half_y + sy) / std::abs(d) : 1e9);
      r += noise(rng);
      BeamUpdate b;
      b.start_x = sx;
      b.start_y = sy;
      b.end_x = sx + r * c;
      b.end_y = sy + r * d;
      b.hit_x = b.end_x;
      b.hit_y = b.end_y;
      b.mark = true;
      b.clear = true;
      scan.push_back(b);
    }
    const IntegrationStats a = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats b =
        integrateBeams(blocks, scan, &block_scratch, ClearingWalk::kBlockSkip, 1);
    const IntegrationStats c =
        integrateBeams(threaded, scan, &threaded_scratch, ClearingWalk::kBlockSkip, 2, 0);
    expectSameStats(b, a);
    const IntegrationStats d =
        integrateBeams(reverse, scan, &reverse_scratch, ClearingWalk::kReverseQuery);
    expectSameStats(c, a);
    expectSameStats(d, a);
    ASSERT_FALSE(threaded_scratch.bands.empty());
    expectBandsStayInTheirRows(threaded_scratch, g.sizeX());
    for (std::size_t i = 0; i < g.cellCount(); ++i) {
      ASSERT_EQ(blocks.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
      ASSERT_EQ(threaded.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
    }
  }
  // The outside stayed unseen and the walls occupied.
  EXPECT_EQ(per_ray.state(g.index(1, 1)), CellState::kUnknown);
  CellIndex wall;
  ASSERT_TRUE(g.worldToCell(half_x + 0.001, 0.3, &wall));
  EXPECT_EQ(per_ray.state(g.index(wall.x, wall.y)), CellState::kOccupied);
}

TEST(ScanClearing, AutoTakesMarkSweepForDenseRaysOverUnseenSpace) {
  // Rays crossing at least half the box's cells over a box less than a quarter saturated.
  EXPECT_TRUE(autoChoosesMarkSweep(500, 1000, 0.0));
  EXPECT_TRUE(autoChoosesMarkSweep(2000, 1000, 0.24));
  EXPECT_FALSE(autoChoosesMarkSweep(499, 1000, 0.0));    // sparse: the sweep would cost more
  EXPECT_FALSE(autoChoosesMarkSweep(2000, 1000, 0.25));  // seen space: the block walk's case
  // A first dense scan on a real grid takes it, and its marks are all cleared afterwards.
  const GridGeometry g(300, 260, 0.05, -7.5, -6.5);
  LogOddsGrid grid(g);
  IntegrationScratch scratch;
  std::mt19937 rng(5);
  integrateBeams(grid, randomScan(&rng, 0.01, 0.02, 3600, 7.0), &scratch, ClearingWalk::kAuto);
  ASSERT_EQ(scratch.crossed.size(), g.cellCount());
  for (const std::uint8_t mark : scratch.crossed) ASSERT_EQ(mark, 0);
}

TEST(ScanClearing, ReverseQueryForgetsSaturatedBlocksWhenTheGridChanges) {
  // The reverse query remembers which blocks are all saturated free from one scan to the next.
  // Any change of the grid between scans (a cell set, a decay, an assignment) must drop that
  // memory: a cell set back to unknown inside a remembered block must take its miss again.
  const GridGeometry g(160, 150, 0.05, -4.0, -3.7);
  LogOddsGrid per_ray(g);
  LogOddsGrid reverse(g);
  IntegrationScratch scratch;
  std::mt19937 rng(21);
  const auto check = [&](int s) {
    auto scan = randomScan(&rng, 0.013, -0.021, 3600, 2.5);
    for (BeamUpdate& b : scan) {  // no hits within 1.8 m: the blocks there saturate free
      if (std::hypot(b.end_x - b.start_x, b.end_y - b.start_y) < 1.8) b.mark = false;
    }
    const IntegrationStats a = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats b = integrateBeams(reverse, scan, &scratch, ClearingWalk::kReverseQuery);
    expectSameStats(b, a);
    for (std::size_t i = 0; i < g.cellCount(); ++i)
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
  };
  for (int s = 0; s < 30; ++s) check(s);  // saturates the disc around the sensor
  const std::size_t near_sensor = g.index(85, 72);
  ASSERT_EQ(reverse.units(near_sensor), reverse.clampMinUnits());
  for (int s = 30; s < 36; ++s) {
    // Back to unknown near the sensor, in both, in a different way each time.
    if (s % 3 == 0) {
      per_ray.setLogOdds(near_sensor, 0.0);
      reverse.setLogOdds(near_sensor, 0.0);
    } else if (s % 3 == 1) {
      per_ray.decay(0.5, CellBounds{80, 70, 90, 75});
      reverse.decay(0.5, CellBounds{80, 70, 90, 75});
    } else {
      LogOddsGrid other = reverse;
      other.setLogOdds(near_sensor, 0.0);
      reverse = other;
      per_ray.setLogOdds(near_sensor, 0.0);
    }
    check(s);
  }
}

TEST(ScanClearing, ReverseQueryMatchesOnRaysThroughLatticeCorners) {
  // Rays from a lattice point to lattice points: many pass exactly through cell corners, where
  // the walk steps diagonally (RayWalk's tie); the reverse query must visit (and count) exactly
  // the walk's cells. Repeated, so the free space saturates and the query's skips matter.
  const GridGeometry g(120, 110, 0.05, -3.0, -2.75);
  LogOddsGrid per_ray(g);
  LogOddsGrid reverse(g);
  IntegrationScratch scratch;
  std::vector<BeamUpdate> scan;
  const double ox = 0.0;  // a lattice point (cell corner)
  const double oy = 0.0;
  for (int i = -55; i <= 55; i += 1) {
    for (int j = -50; j <= 50; j += 7) {
      if (i == 0 && j == 0) continue;
      for (const auto& [ex, ey] : {std::make_pair(i, j), std::make_pair(j, i)}) {
        BeamUpdate b;
        b.start_x = ox;
        b.start_y = oy;
        b.end_x = ox + 0.05 * ex;
        b.end_y = oy + 0.05 * ey;
        b.clear = true;
        b.mark = (i + j) % 3 != 0;
        b.clear_end_cell = (i + j) % 3 == 0;
        b.hit_x = b.end_x;
        b.hit_y = b.end_y;
        scan.push_back(b);
      }
    }
  }
  for (int s = 0; s < 25; ++s) {
    const IntegrationStats a = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats b = integrateBeams(reverse, scan, &scratch, ClearingWalk::kReverseQuery);
    expectSameStats(b, a);
    for (std::size_t i = 0; i < g.cellCount(); ++i)
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
  }
}

TEST(ScanClearing, ReverseQueryLeavesTheSideCellsOfACornerAlone) {
  // Few rays through corners, apart from each other far from the start: a side cell of a corner
  // the walk crosses diagonally is no other ray's cell, so a query that visited it would differ.
  const GridGeometry g(120, 110, 0.05, -3.0, -2.75);
  LogOddsGrid per_ray(g);
  LogOddsGrid reverse(g);
  IntegrationScratch scratch;
  std::vector<BeamUpdate> scan;
  const int dirs[][2] = {{1, 1}, {2, 1}, {1, 2}, {3, 2}, {2, 3}, {5, 1}};
  for (const auto& d : dirs) {
    for (const int sx : {-1, 1}) {
      for (const int sy : {-1, 1}) {
        for (const int k : {4, 9, 15}) {
          const int ex = sx * d[0] * k;
          const int ey = sy * d[1] * k;
          if (std::abs(ex) > 55 || std::abs(ey) > 50) continue;
          BeamUpdate b;
          b.end_x = 0.05 * ex;  // from (0, 0), a cell corner
          b.end_y = 0.05 * ey;
          b.clear = true;
          b.mark = k != 9;
          b.clear_end_cell = k == 9;
          b.hit_x = b.end_x;
          b.hit_y = b.end_y;
          scan.push_back(b);
        }
      }
    }
  }
  for (int s = 0; s < 3; ++s) {
    const IntegrationStats a = integrateBeams(per_ray, scan, nullptr, ClearingWalk::kPerRay);
    const IntegrationStats b = integrateBeams(reverse, scan, &scratch, ClearingWalk::kReverseQuery);
    expectSameStats(b, a);
    for (std::size_t i = 0; i < g.cellCount(); ++i)
      ASSERT_EQ(reverse.rawCells()[i], per_ray.rawCells()[i]) << "scan " << s << " cell " << i;
  }
}
