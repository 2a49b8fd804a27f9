#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/scan_integrator.h"

using namespace downstream_perception;  // NOLINT

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct Fixture {
  // 10 m x 10 m at 0.1 m, origin (-5, -5): the sensor at the origin sits in cell (50, 50).
  LogOddsGrid grid = defaultGrid();
  ScanIntegratorConfig config = defaultConfig();
  // Built in a function, not in the member's initializer: there GCC 12 warns of a dangling
  // pointer to the constructor's default LogOddsConfig argument (a false positive; the grid keeps
  // copies).
  static LogOddsGrid defaultGrid() { return LogOddsGrid(GridGeometry(100, 100, 0.1, -5.0, -5.0)); }
  static ScanIntegratorConfig defaultConfig() {
    ScanIntegratorConfig c;
    c.obstacle_max_range = 4.0;
    c.raytrace_max_range = 4.47;  // off cell edges: exact expectations
    return c;
  }
  CellState at(double x, double y) const {
    CellIndex c;
    EXPECT_TRUE(grid.geometry().worldToCell(x, y, &c));
    return grid.state(grid.geometry().index(c.x, c.y));
  }
  int unitsAt(double x, double y) const {
    return grid.units(grid.geometry().index(grid.geometry().worldToCellUnbounded(x, y).x,
                                            grid.geometry().worldToCellUnbounded(x, y).y));
  }
  IntegrationStats scan(const std::vector<float>& ranges, double angle_min, double inc,
                        const Pose2D& pose = {}, double range_min = 0.05, double range_max = 30.0) {
    ScanIntegrator integrator(config);
    LaserScanView view{ranges.data(), ranges.size(), angle_min, inc, range_min, range_max};
    return integrator.integrate(grid, view, pose);
  }
};
}  // namespace

TEST(ScanIntegrator, OneBeamClearsThenMarks) {
  Fixture f;
  const auto stats = f.scan({2.05f}, 0.0, 0.01);
  // Hit at x = 2.05 -> cell 70; cleared cells 50..69 (20 cells) along y = 0 (row 50).
  EXPECT_EQ(stats.cells_marked, 1u);
  EXPECT_EQ(stats.cells_cleared, 20u);
  EXPECT_EQ(f.unitsAt(2.05, 0.0), f.grid.hitUnits());
  EXPECT_EQ(f.unitsAt(1.0, 0.0), f.grid.missUnits());
  EXPECT_EQ(f.unitsAt(0.0, 0.0), f.grid.missUnits());  // the sensor's own cell is crossed
  EXPECT_EQ(f.unitsAt(2.25, 0.0), 0);                  // behind the hit: untouched
  EXPECT_DOUBLE_EQ(stats.clearMarkRatio(), 20.0);
  EXPECT_EQ(stats.touched.min_x, 50);
  EXPECT_EQ(stats.touched.max_x, 70);
}

TEST(ScanIntegrator, RepeatedScansReachTheThresholds) {
  Fixture f;
  for (int i = 0; i < 3; ++i) f.scan({2.05f}, 0.0, 0.01);
  EXPECT_EQ(f.at(2.05, 0.0), CellState::kOccupied);  // 3 hits -> 2.54 > 2
  EXPECT_EQ(f.at(1.0, 0.0), CellState::kUnknown);    // 3 misses -> -1.22
  for (int i = 0; i < 3; ++i) f.scan({2.05f}, 0.0, 0.01);
  EXPECT_EQ(f.at(1.0, 0.0), CellState::kFree);  // 6 misses -> -2.43 < -2
}

TEST(ScanIntegrator, Rep117SpecialValues) {
  Fixture f;
  // NaN: ignored.  -Inf: ignored.  +Inf: clears to raytrace_max_range, marks nothing.
  const auto stats = f.scan({kNaN, -kInf, kInf}, 0.0, M_PI / 2);  // beams at 0, 90, 180 deg
  EXPECT_EQ(stats.beams_invalid, 2u);
  EXPECT_EQ(stats.beams_no_return, 1u);
  EXPECT_EQ(stats.cells_marked, 0u);
  EXPECT_EQ(f.unitsAt(1.0, 0.0), 0);                     // NaN beam did nothing
  EXPECT_EQ(f.unitsAt(0.0, 1.0), 0);                     // -Inf beam did nothing
  EXPECT_EQ(f.unitsAt(-4.45, 0.0), f.grid.missUnits());  // +Inf beam cleared out to 4.47 m
  EXPECT_EQ(f.unitsAt(-4.55, 0.0), 0);                   // and no further
  EXPECT_EQ(stats.cells_cleared, 46u);  // cells 50 down to 5 (x = -4.47 lies in cell 5)
}

TEST(ScanIntegrator, InfIsNotValidIgnoresNoReturnBeams) {
  Fixture f;
  f.config.inf_is_valid = false;
  const auto stats = f.scan({kInf}, 0.0, 0.1);
  EXPECT_EQ(stats.beams_invalid, 1u);
  EXPECT_EQ(stats.cells_cleared, 0u);
}

TEST(ScanIntegrator, OutsideRangeMinMaxIsDiscardedPerLaserScanMsg) {
  Fixture f;
  const auto stats = f.scan({0.01f, 35.0f, 3.0f}, 0.0, M_PI / 2, {}, 0.05, 30.0);
  EXPECT_EQ(stats.beams_invalid, 2u);
  EXPECT_EQ(stats.cells_marked, 1u);
  EXPECT_EQ(f.unitsAt(0.0, 3.05), 0);  // the 35 m beam along +y did nothing
}

TEST(ScanIntegrator, RangeMaxAsNoReturnOption) {
  Fixture f;
  auto stats = f.scan({10.0f}, 0.0, 0.1, {}, 0.05, 10.0);  // a return exactly at range_max
  EXPECT_EQ(stats.beams_no_return, 0u);
  EXPECT_EQ(stats.beams_beyond_obstacle_range, 1u);  // 10 m > obstacle_max_range 4 m
  f.config.range_max_is_no_return = true;
  stats = f.scan({10.0f}, 0.0, 0.1, {}, 0.05, 10.0);
  EXPECT_EQ(stats.beams_no_return, 1u);
}

TEST(ScanIntegrator, ObstacleAndRaytraceRanges) {
  Fixture f;
  // A return at 4.2 m: beyond obstacle_max_range 4.0 -> not marked; cleared up to 4.2 m, and the
  // hit cell itself is not cleared.
  auto stats = f.scan({4.25f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_marked, 0u);
  EXPECT_EQ(stats.beams_beyond_obstacle_range, 1u);
  EXPECT_EQ(f.unitsAt(4.15, 0.0), f.grid.missUnits());
  EXPECT_EQ(f.unitsAt(4.25, 0.0), 0);
  // A return at 4.85 m is truncated by raytrace_max_range 4.47: the cell containing 4.47 is a
  // pass-through and is cleared; nothing beyond.
  Fixture g;
  stats = g.scan({4.85f}, 0.0, 0.1);
  EXPECT_EQ(g.unitsAt(4.45, 0.0), g.grid.missUnits());
  EXPECT_EQ(g.unitsAt(4.55, 0.0), 0);
  // raytrace_min_range: nothing cleared nearer than 1 m.
  Fixture h;
  h.config.raytrace_min_range = 1.0;
  h.scan({3.05f}, 0.0, 0.1);
  EXPECT_EQ(h.unitsAt(0.55, 0.0), 0);
  EXPECT_EQ(h.unitsAt(1.05, 0.0), h.grid.missUnits());
  EXPECT_EQ(h.unitsAt(3.05, 0.0), h.grid.hitUnits());
  // obstacle_min_range: a return nearer than it clears but does not mark.
  Fixture k;
  k.config.obstacle_min_range = 0.5;
  stats = k.scan({0.35f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_marked, 0u);
}

TEST(ScanIntegrator, MarkingAndClearingSwitches) {
  Fixture f;
  f.config.clearing = false;
  auto stats = f.scan({2.05f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_cleared, 0u);
  EXPECT_EQ(stats.cells_marked, 1u);
  Fixture g;
  g.config.marking = false;
  stats = g.scan({2.05f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_marked, 0u);
  EXPECT_EQ(stats.cells_cleared, 20u);
  EXPECT_EQ(g.unitsAt(2.05, 0.0), 0);  // a clearing-only source never clears its hit cell
}

TEST(ScanIntegrator, EachCellUpdatedOncePerScanAndHitsWin) {
  Fixture f;
  // 100 beams in a narrow fan all cross the first cells: each cell still gets one miss.
  std::vector<float> ranges(100, 3.0f);
  auto stats = f.scan(ranges, -0.05, 0.001);
  EXPECT_EQ(f.unitsAt(0.0, 0.0), f.grid.missUnits());
  EXPECT_EQ(f.unitsAt(0.5, 0.0), f.grid.missUnits());
  // A grazing beam passes through the cell another beam of the same scan hits: the hit wins.
  Fixture g;
  // Beam A hits (2.05, 0.05) exactly; beam B, to (3.0, 0.0), crosses that cell's row at y in [0,
  // 0.1).
  const float ra = static_cast<float>(std::hypot(2.05, 0.05));
  const double aa = std::atan2(0.05, 2.05);
  std::vector<float> two = {3.0f, ra};
  stats = g.scan(two, 0.0, aa);
  EXPECT_EQ(g.unitsAt(2.05, 0.05), g.grid.hitUnits());
  EXPECT_EQ(stats.cells_marked, 2u);
  // No flags remain set after the scan.
  for (std::size_t i = 0; i < g.grid.geometry().cellCount(); ++i) ASSERT_FALSE(g.grid.flagged(i));
}

TEST(ScanIntegrator, PoseRotatesAndTranslatesBeams) {
  Fixture f;
  // Sensor at (1.05, 1.05) facing +y (yaw 90 deg): a beam at angle 0 of 2 m hits (1.05, 3.05).
  f.scan({2.0f}, 0.0, 0.1, {1.05, 1.05, M_PI / 2});
  EXPECT_EQ(f.unitsAt(1.05, 3.05), f.grid.hitUnits());
  EXPECT_EQ(f.unitsAt(1.05, 2.0), f.grid.missUnits());
  EXPECT_EQ(f.unitsAt(1.05, 0.95), 0);  // behind the sensor
}

TEST(ScanIntegrator, ChangedBoundsFollowStateChanges) {
  Fixture f;
  auto stats = f.scan({2.05f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_changed, 0u);  // one update leaves every cell unknown
  EXPECT_TRUE(stats.changed.empty());
  f.scan({2.05f}, 0.0, 0.1);
  stats = f.scan({2.05f}, 0.0, 0.1);
  EXPECT_EQ(stats.cells_changed, 1u);  // the hit cell became occupied on the third scan
  EXPECT_EQ(stats.changed.min_x, 70);
  EXPECT_EQ(stats.changed.max_x, 70);
}

TEST(ScanIntegrator, RejectsMalformedScans) {
  Fixture f;
  std::vector<float> r(10, 1.0f);
  ScanIntegrator integrator(f.config);
  LaserScanView bad{r.data(), r.size(), 0.0, 0.0, 0.05, 30.0};  // zero increment
  EXPECT_FALSE(bad.validate().empty());
  EXPECT_THROW(integrator.integrate(f.grid, bad, {}), std::invalid_argument);
  LaserScanView nan_angle{r.data(), r.size(), std::nan(""), 0.1, 0.05, 30.0};
  EXPECT_FALSE(nan_angle.validate().empty());
  LaserScanView bad_range{r.data(), r.size(), 0.0, 0.1, 5.0, 1.0};
  EXPECT_FALSE(bad_range.validate().empty());
  LaserScanView empty{r.data(), 0, 0.0, 0.1, 0.05, 30.0};
  EXPECT_FALSE(empty.validate().empty());
  LaserScanView too_wide{r.data(), r.size(), 0.0, 1.0, 0.05, 30.0};  // 10 rad
  EXPECT_FALSE(too_wide.validate().empty());
  ScanIntegratorConfig c;
  c.raytrace_max_range = -1.0;
  EXPECT_FALSE(c.validate().empty());
  EXPECT_THROW(ScanIntegrator{c}, std::invalid_argument);
}

TEST(ScanIntegrator, HundredThousandRandomScansNeverWriteOutOfBounds) {
  // The grid sits inside a larger vector guarded by sentinels; poses may lie outside the grid
  // and ranges are anything, including specials. Address sanitizer is not needed: the guard
  // pattern and the flag invariant catch stray writes.
  const GridGeometry geometry(37, 23, 0.1, -1.0, -1.0);
  LogOddsGrid grid(geometry);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 20.0;
  config.raytrace_max_range = 25.0;
  ScanIntegrator integrator(config);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> pos(-4.0, 6.0);
  std::uniform_real_distribution<double> ang(-M_PI, M_PI);
  std::uniform_real_distribution<float> range(-1.0f, 30.0f);
  std::uniform_int_distribution<int> special(0, 9);
  std::vector<float> ranges(16);
  std::size_t updates = 0;
  for (int n = 0; n < 100000; ++n) {
    for (auto& r : ranges) {
      const int s = special(rng);
      r = s == 0 ? kNaN : s == 1 ? kInf : s == 2 ? -kInf : range(rng);
    }
    LaserScanView view{ranges.data(), ranges.size(), ang(rng), 0.39, 0.0, 30.0};
    const auto stats = integrator.integrate(grid, view, {pos(rng), pos(rng), ang(rng)});
    updates += stats.cells_cleared + stats.cells_marked;
    if (!stats.touched.empty()) {
      ASSERT_GE(stats.touched.min_x, 0);
      ASSERT_GE(stats.touched.min_y, 0);
      ASSERT_LT(stats.touched.max_x, geometry.sizeX());
      ASSERT_LT(stats.touched.max_y, geometry.sizeY());
    }
  }
  EXPECT_GT(updates, 100000u);  // the scans really hit the grid
  for (std::size_t i = 0; i < geometry.cellCount(); ++i) {
    ASSERT_FALSE(grid.flagged(i));
    ASSERT_LE(std::abs(grid.logOdds(i)), 8.0);
  }
}

TEST(MovingScan, PerBeamPosesPutAWallWhereItIs) {
  // A robot turning at 2 rad/s during a 0.1 s sweep (0.2 rad) sees a wall at x = 2 m. Each
  // beam's range is generated from the pose at its own time; with the per-beam correction every
  // return lands on the wall, the rigid pose at the first beam smears it by up to 0.4 m.
  const std::size_t n = 101;
  const double angle_min = -0.5;
  const double inc = 1.0 / 100.0;
  const Pose2D first{0.0, 0.0, 0.0};
  const Pose2D last{0.0, 0.0, 0.2};
  std::vector<float> ranges(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double yaw = 0.2 * static_cast<double>(k) / (n - 1);
    ranges[k] = static_cast<float>(2.0 / std::cos(yaw + angle_min + k * inc));
  }
  ScanIntegratorConfig config;
  config.obstacle_max_range = 5.0;
  config.raytrace_max_range = 5.0;
  ScanIntegrator integrator(config);
  const LaserScanView view{ranges.data(), n, angle_min, inc, 0.05, 30.0};
  const auto hit_xs = [](const std::vector<BeamUpdate>& beams) {
    double lo = 1e9, hi = -1e9;
    for (const BeamUpdate& b : beams) {
      lo = std::min(lo, b.hit_x);
      hi = std::max(hi, b.hit_x);
    }
    return std::make_pair(lo, hi);
  };
  std::vector<BeamUpdate> corrected;
  IntegrationStats stats;
  integrator.beamsFromMovingScan(view, first, last, &corrected, &stats);
  ASSERT_EQ(corrected.size(), n);
  EXPECT_EQ(stats.beams, n);
  const auto [lo_c, hi_c] = hit_xs(corrected);
  EXPECT_NEAR(lo_c, 2.0, 1e-5);
  EXPECT_NEAR(hi_c, 2.0, 1e-5);
  std::vector<BeamUpdate> rigid;
  IntegrationStats rigid_stats;
  integrator.beamsFromScan(view, first, &rigid, &rigid_stats);
  const auto [lo_r, hi_r] = hit_xs(rigid);
  EXPECT_GT(hi_r - lo_r, 0.05);  // the smear the correction removes
  // Same pose at both ends: identical to the rigid scan.
  std::vector<BeamUpdate> same;
  integrator.beamsFromMovingScan(view, first, first, &same, &stats);
  for (std::size_t k = 0; k < n; ++k) EXPECT_NEAR(same[k].hit_x, rigid[k].hit_x, 1e-9);
}

// Issue 17 item 4: a beam from a sensor 1e18 m away (a tf gone wrong) was clipped to a start
// cell outside the grid and the pointer walk read and wrote past the cell array.
TEST(ScanIntegrator, FarAwaySensorNeverWalksOutOfTheGrid) {
  const GridGeometry geometry(200, 200, 0.05, -5.0, -5.0);
  LogOddsGrid grid(geometry);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const double far : {1e12, 1e15, 1e18, 1e300}) {
    std::vector<BeamUpdate> beams;
    for (int n = 0; n < 2000; ++n) {
      BeamUpdate b;
      const double a = M_PI * unit(rng);
      b.start_x = far * std::cos(a);
      b.start_y = far * std::sin(a);
      b.end_x = 4.9 * unit(rng);
      b.end_y = 4.9 * unit(rng);
      b.clear = true;
      b.clear_end_cell = n % 2 == 0;
      b.mark = n % 3 == 0;
      b.hit_x = b.end_x;
      b.hit_y = b.end_y;
      beams.push_back(b);
      std::swap(b.start_x, b.end_x);  // and the beam the other way, ending far away
      std::swap(b.start_y, b.end_y);
      b.mark = false;
      beams.push_back(b);
    }
    const IntegrationStats stats = integrateBeams(grid, beams);
    ASSERT_FALSE(stats.touched.empty());
    EXPECT_GE(stats.touched.min_x, 0) << far;
    EXPECT_GE(stats.touched.min_y, 0) << far;
    EXPECT_LT(stats.touched.max_x, geometry.sizeX()) << far;
    EXPECT_LT(stats.touched.max_y, geometry.sizeY()) << far;
    EXPECT_GT(stats.cells_cleared, 2000u);
  }
  for (std::size_t i = 0; i < geometry.cellCount(); ++i) ASSERT_FALSE(grid.flagged(i));
}

TEST(ScanIntegratorConfig, RangesAreBounded) {
  ScanIntegratorConfig ok;
  ok.obstacle_max_range = ScanIntegratorConfig::kMaxRangeM;
  ok.raytrace_max_range = ScanIntegratorConfig::kMaxRangeM;
  EXPECT_EQ(ok.validate(), "");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const double bad : {1e15, 1.0001e4, std::numeric_limits<double>::infinity(), nan, -0.5}) {
    ScanIntegratorConfig c;
    c.raytrace_max_range = bad;
    EXPECT_NE(c.validate().find("raytrace_max_range"), std::string::npos) << bad;
    c = ScanIntegratorConfig{};
    c.obstacle_max_range = bad;
    EXPECT_NE(c.validate().find("obstacle_max_range"), std::string::npos) << bad;
    EXPECT_THROW(ScanIntegrator{c}, std::invalid_argument);
  }
  ScanIntegratorConfig reversed;
  reversed.raytrace_min_range = 5.0;
  reversed.raytrace_max_range = 4.0;
  EXPECT_FALSE(reversed.validate().empty());
}
