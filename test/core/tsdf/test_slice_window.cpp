// The slice's rolling window (tsdf_slice.h, sliceWindowGeometry; the nodelet's ~slice_window_m
// and ~slice_max_cells): hand-derived grids for lattice snapping, the intersection with the
// blocks' extent, the cell cap and an empty window; the slice and the band's ESDF over a window
// equal the whole map's inside it, cell for cell (the ESDF runs over the window grown by its cap).
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "downstream_perception/core/tsdf/esdf_band.h"
#include "downstream_perception/core/tsdf/tsdf_map.h"
#include "downstream_perception/core/tsdf/tsdf_slice.h"
#include "esdf_test_helpers.h"
#include "tsdf_test_helpers.h"

using namespace downstream_perception;        // NOLINT
using namespace downstream_perception::test;  // NOLINT

namespace {

// Blocks -2..2 along x and -1..1 along y (8 columns each): columns x -16..23, y -8..15.
const ColumnBox kColumns{-16, -8, 23, 15};
constexpr double kVoxel = 0.1;

SliceWindow window(double cx, double cy, double side_m,
                   std::size_t max_cells = SliceWindow::kDefaultMaxCells) {
  SliceWindow w;
  w.centre_x_m = cx;
  w.centre_y_m = cy;
  w.side_m = side_m;
  w.max_cells = max_cells;
  return w;
}

void expectGrid(const GridGeometry& g, int nx, int ny, double ox, double oy) {
  EXPECT_EQ(g.sizeX(), nx);
  EXPECT_EQ(g.sizeY(), ny);
  EXPECT_NEAR(g.originX(), ox, 1e-12);
  EXPECT_NEAR(g.originY(), oy, 1e-12);
  if (nx > 0) {
    EXPECT_DOUBLE_EQ(g.resolution(), kVoxel);
  }
}

}  // namespace

TEST(SliceWindow, ZeroSideIsTheBlocksWholeExtent) {
  bool capped = true;
  // 40 x 24 columns from column (-16, -8): origin half a voxel below its centre.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.0), &capped), 40, 24,
             -1.65, -0.85);
  EXPECT_FALSE(capped);
}

TEST(SliceWindow, SnapsToTheVoxelLattice) {
  // 1 m at 10 cm: 10 columns; the centre x = 0.26 is nearest column 3 (floor(2.6 + 0.5)),
  // which is column n / 2 = 5 of the window: columns -2..7, origin -2.5 voxels = -0.25 m.
  // y = -0.04: column 0, columns -5..4, origin -0.55 m.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 1.0)), 10, 10, -0.25, -0.55);
  // The sensor moving within column 3 (x in [0.25, 0.35)) moves no cell: no shimmer.
  for (const double x : {0.2501, 0.2999, 0.3, 0.3499}) {
    expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(x, -0.04, 1.0)), 10, 10, -0.25, -0.55);
  }
  // Into column 4: one whole voxel.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.3501, -0.04, 1.0)), 10, 10, -0.15,
             -0.55);
  // An odd count: 0.5 m = 5 columns, column 3 at index 2: columns 1..5.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.5)), 5, 5, 0.05, -0.25);
  // A side below a voxel is one column.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.01)), 1, 1, 0.25, -0.05);
}

TEST(SliceWindow, IsCutToTheBlocksExtent) {
  // Centre (2.2, 1.4): columns 22 and 14, windows 17..26 and 9..18, cut at 23 and 15: 7 x 7
  // from (17, 9), origin (1.65, 0.85).
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(2.2, 1.4, 1.0)), 7, 7, 1.65, 0.85);
  // Across the lower-left corner: columns -17 and -9 (floor(-17.2 + 0.5), floor(-9.3 + 0.5)),
  // windows -22..-13 and -14..-5 cut at -16 and -8: 4 x 4.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(-1.72, -0.93, 1.0)), 4, 4, -1.65, -0.85);
}

TEST(SliceWindow, EmptyWhenItMissesTheBlocksOrThereAreNone) {
  // Columns 95..104: beyond column 23.
  EXPECT_EQ(sliceWindowGeometry(kColumns, kVoxel, window(10.0, 0.0, 1.0)).cellCount(), 0u);
  // Misses along y only.
  EXPECT_EQ(sliceWindowGeometry(kColumns, kVoxel, window(0.0, -1.5, 1.0)).cellCount(), 0u);
  // An empty map: nothing, with or without a window.
  EXPECT_EQ(sliceWindowGeometry(ColumnBox{}, kVoxel, window(0.0, 0.0, 1.0)).cellCount(), 0u);
  EXPECT_EQ(sliceWindowGeometry(ColumnBox{}, kVoxel, window(0.0, 0.0, 0.0)).cellCount(), 0u);
}

TEST(SliceWindow, TheCapCutsToASquareAroundTheCentre) {
  bool capped = false;
  // The whole extent is 960 cells: a cap of 960 keeps it...
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.0, 960), &capped), 40, 24,
             -1.65, -0.85);
  EXPECT_FALSE(capped);
  // ... 959 cuts it to floor(sqrt(959)) = 30 columns around column (3, 0): x -12..17, y -15..14
  // cut at -8: 30 x 23 from (-12, -8).
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.0, 959), &capped), 30, 23,
             -1.25, -0.85);
  EXPECT_TRUE(capped);
  // 100 cells: the 10 x 10 square of the 1 m window.
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 0.0, 100), &capped), 10, 10,
             -0.25, -0.55);
  EXPECT_TRUE(capped);
  // A window within the cap is not cut; a larger one is (2 m = 400 cells > 100).
  sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 1.0, 100), &capped);
  EXPECT_FALSE(capped);
  expectGrid(sliceWindowGeometry(kColumns, kVoxel, window(0.26, -0.04, 2.0, 100), &capped), 10, 10,
             -0.25, -0.55);
  EXPECT_TRUE(capped);
  // Blocks a thousand kilometres apart (no grid holds their extent): cut to the default cap's
  // 2,000 x 2,000 around the sensor, never refused.
  const ColumnBox wide{-1000, -1000, 10000000, 10000000};
  expectGrid(sliceWindowGeometry(wide, kVoxel, window(0.0, 0.0, 0.0), &capped), 2000, 2000, -100.05,
             -100.05);
  EXPECT_TRUE(capped);
}

TEST(SliceWindow, InvalidWindowsAreRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const SliceWindow& w :
       {window(0.0, 0.0, -1.0), window(0.0, 0.0, nan), window(0.0, 0.0, inf), window(0.0, 0.0, 2e5),
        window(nan, 0.0, 1.0), window(0.0, inf, 1.0), window(0.0, 0.0, 1.0, 0),
        window(0.0, 0.0, 1.0, GridGeometry::kMaxCells + 1)}) {
    EXPECT_FALSE(w.validate().empty()) << w.side_m << " " << w.max_cells;
    EXPECT_THROW(sliceWindowGeometry(kColumns, kVoxel, w), std::invalid_argument);
  }
  EXPECT_TRUE(window(0.0, 0.0, 0.0).validate().empty());
  EXPECT_TRUE(window(0.0, 0.0, 1e5, GridGeometry::kMaxCells).validate().empty());
}

TEST(SliceWindow, BlockColumnsOfAMap) {
  TsdfConfig c;
  c.voxel_size_m = kVoxel;
  TsdfMap map(c);
  EXPECT_TRUE(blockColumns(map).empty());
  // Voxels (-9, 3, 0) and (20, 14, 5): blocks (-2, 0) and (2, 1) of 8 columns.
  fill(&map, {-9, 3, 0}, {-9, 3, 0}, [](const Eigen::Vector3d&) { return 0.5; });
  fill(&map, {20, 14, 5}, {20, 14, 5}, [](const Eigen::Vector3d&) { return 0.5; });
  const ColumnBox box = blockColumns(map);
  EXPECT_EQ(box.min_x, -16);
  EXPECT_EQ(box.min_y, 0);
  EXPECT_EQ(box.max_x, 23);
  EXPECT_EQ(box.max_y, 15);
  // The whole extent's window grid is sliceGeometry's.
  EXPECT_EQ(sliceWindowGeometry(box, kVoxel, window(0.0, 0.0, 0.0)), sliceGeometry(map));
}

TEST(SliceWindow, AnExtentBeyondAGridIsRefusedNotWrapped) {
  TsdfConfig c;
  c.voxel_size_m = kVoxel;
  TsdfMap map(c);
  // The farthest blocks the map's index range allows on either side: 2^31 columns apart, past
  // an int (the old per-axis count wrapped to a negative size) and past GridGeometry's limit.
  constexpr int kFarBlock = TsdfMap::kMaxVoxelIndex / kTsdfBlockSide;
  ASSERT_NE(map.allocate({-kFarBlock, 0, 0}), nullptr);
  ASSERT_NE(map.allocate({kFarBlock - 1, 0, 0}), nullptr);
  const ColumnBox box = blockColumns(map);
  EXPECT_EQ(box.width(), std::int64_t{1} << 31);
  EXPECT_THROW(sliceGeometry(map), std::invalid_argument);
  // A window around the sensor still gives a grid over such a map.
  const GridGeometry g = sliceWindowGeometry(box, kVoxel, window(0.0, 0.0, 2.0));
  EXPECT_EQ(g.sizeX(), 20);
  EXPECT_EQ(g.sizeY(), kTsdfBlockSide);  // the one block row
}

namespace {

/// Windows over the 5 cm room (blocks cover about -2.4 .. 2.4 m): inside, across a wall, over a
/// corner, one voxel wide, and the whole extent.
struct RoomWindow {
  double x, y, side;
};
const RoomWindow kRoomWindows[] = {{0.3, -0.2, 1.0},   {1.9, 0.4, 1.2},   {-2.3, 2.2, 1.5},
                                   {0.62, 0.58, 0.05}, {-0.5, -0.6, 0.8}, {0.0, 0.0, 0.0}};

}  // namespace

TEST(SliceWindow, SliceInAWindowIsTheWholeSliceCropped) {
  RoomScene scene;
  scene.offset = Eigen::Vector3d(0.037, 0.061, 0.023);
  const TsdfMap map = filledRoom(0.05, scene);
  const GridGeometry whole = sliceGeometry(map);
  const TsdfSliceConfig band;
  const std::vector<SliceCell> all = sliceTsdf(map, whole, band);
  for (const RoomWindow& rw : kRoomWindows) {
    SliceWindow w;
    w.centre_x_m = rw.x;
    w.centre_y_m = rw.y;
    w.side_m = rw.side;
    const GridGeometry g = sliceWindowGeometry(blockColumns(map), map.voxelSize(), w);
    ASSERT_GT(g.cellCount(), 0u);
    const std::vector<SliceCell> cells = sliceTsdf(map, g, band);
    const CellIndex o = whole.worldToCellUnbounded(g.originX() + 0.5 * g.resolution(),
                                                   g.originY() + 0.5 * g.resolution());
    std::size_t different = 0;
    for (int y = 0; y < g.sizeY(); ++y) {
      for (int x = 0; x < g.sizeX(); ++x) {
        different += cells[g.index(x, y)] != all[whole.index(o.x + x, o.y + y)];
      }
    }
    EXPECT_EQ(different, 0u) << rw.x << ", " << rw.y << " side " << rw.side;
  }
}

TEST(SliceWindow, BandEsdfInAWindowEqualsTheWholeMapsInsideIt) {
  // Obstacles just outside the window are within the cap of cells inside it: the transform over
  // the window alone would read those cells too far (or at the cap). Grown by the cap and
  // cropped, every value equals the whole map's: 0 cells different, at two caps.
  RoomScene scene;
  scene.offset = Eigen::Vector3d(0.037, 0.061, 0.023);
  const TsdfMap map = filledRoom(0.05, scene);
  for (const double cap : {2.0, 0.3}) {
    EsdfBandConfig c;
    c.max_distance_m = cap;
    const EsdfBandSlice whole = esdfBandSlice(map, c);
    for (const RoomWindow& rw : kRoomWindows) {
      SliceWindow w;
      w.centre_x_m = rw.x;
      w.centre_y_m = rw.y;
      w.side_m = rw.side;
      c.grid = sliceWindowGeometry(blockColumns(map), map.voxelSize(), w);
      const EsdfBandSlice band = esdfBandSlice(map, c);
      const GridGeometry& g = band.grid;
      ASSERT_EQ(g, *c.grid);
      const CellIndex o = whole.grid.worldToCellUnbounded(g.originX() + 0.5 * g.resolution(),
                                                          g.originY() + 0.5 * g.resolution());
      std::size_t different = 0, known = 0, occupied = 0, free = 0;
      for (int y = 0; y < g.sizeY(); ++y) {
        for (int x = 0; x < g.sizeX(); ++x) {
          const float got = band.distance_m[g.index(x, y)];
          const float want = whole.distance_m[whole.grid.index(o.x + x, o.y + y)];
          different += !(got == want || (std::isnan(got) && std::isnan(want)));
          known += !std::isnan(want);
          occupied += want < 0.0f;
          free += want > 0.0f;
        }
      }
      const char* where = "window";
      EXPECT_EQ(different, 0u) << where << " " << rw.x << ", " << rw.y << " side " << rw.side
                               << " cap " << cap;
      EXPECT_EQ(band.stats.columns_occupied, occupied);
      EXPECT_EQ(band.stats.columns_free, free);
      EXPECT_EQ(known, occupied + free);
      EXPECT_GT(band.stats.voxels_in_band, 0u);
      // The padding: at most the cap's reach (ceil(cap / voxel + 1/2) columns) on each side.
      const auto reach = static_cast<std::size_t>(std::ceil(cap / 0.05 + 0.5));
      EXPECT_LE(band.stats.columns_computed, (g.sizeX() + 2 * reach) * (g.sizeY() + 2 * reach));
      EXPECT_GE(band.stats.columns_computed, g.cellCount());
    }
    // The whole map read every known band voxel; a window reads fewer.
    EXPECT_GT(whole.stats.voxels_in_band, 0u);
  }
}

TEST(SliceWindow, BandEsdfPaddingIsBoundedByMaxComputedColumns) {
  // A 1 m window (20 x 20 columns) with a 2 m cap pads 41 columns on each side (102^2 computed).
  // Bounded at 40 x 40 columns the padding narrows to the widest that fits, 10 columns: cells at
  // least 41 - 10 columns inside the window's edge still equal the whole map's.
  RoomScene scene;
  scene.offset = Eigen::Vector3d(0.037, 0.061, 0.023);
  const TsdfMap map = filledRoom(0.05, scene);
  EsdfBandConfig c;
  c.max_distance_m = 2.0;
  const EsdfBandSlice whole = esdfBandSlice(map, c);
  SliceWindow w;
  w.centre_x_m = 0.3;
  w.centre_y_m = -0.2;
  w.side_m = 1.0;
  c.grid = sliceWindowGeometry(blockColumns(map), map.voxelSize(), w);
  ASSERT_EQ(c.grid->sizeX(), 20);
  ASSERT_EQ(c.grid->sizeY(), 20);
  const EsdfBandSlice unbounded = esdfBandSlice(map, c);
  EXPECT_FALSE(unbounded.stats.padding_cut);
  EXPECT_EQ(unbounded.stats.padding_voxels, 41u);  // ceil(2 / 0.05 + 1/2)
  c.max_computed_columns = 40 * 40;
  const EsdfBandSlice band = esdfBandSlice(map, c);
  EXPECT_TRUE(band.stats.padding_cut);
  EXPECT_EQ(band.stats.padding_voxels, 10u);  // 20 + 2 * 10 = 40; 11 would make 42^2
  EXPECT_LE(band.stats.columns_computed, c.max_computed_columns);
  const GridGeometry& g = band.grid;
  const CellIndex o = whole.grid.worldToCellUnbounded(g.originX() + 0.5 * g.resolution(),
                                                      g.originY() + 0.5 * g.resolution());
  // The window lies 41 - 10 = 31 columns deep at most; no cell is that far from the edge, so
  // check the rule on the cells it covers: equal wherever the whole map's nearest obstacle lies
  // within the computed box, never nearer than the whole map's anywhere.
  std::size_t compared = 0;
  std::size_t within = 0;
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      const float got = band.distance_m[g.index(x, y)];
      const float want = whole.distance_m[whole.grid.index(o.x + x, o.y + y)];
      if (std::isnan(want)) continue;
      ++compared;
      // Obstacles missed (free cells) or free columns missed (occupied): never nearer.
      EXPECT_GE(std::abs(got), std::abs(want)) << x << ", " << y;
      const int edge = std::min({x, y, g.sizeX() - 1 - x, g.sizeY() - 1 - y});
      // Within the computed box: the nearest column of the other kind is at most edge + 10
      // columns away in every direction.
      if (std::abs(want) / 0.05f + 0.5f <= static_cast<float>(edge + 10)) {
        ++within;
        EXPECT_EQ(got, want) << x << ", " << y;
      }
    }
  }
  EXPECT_GT(compared, 300u);
  EXPECT_GT(within, 20u);
  // Bounded below the grid itself: no padding, the grid still computed.
  c.max_computed_columns = 100;
  const EsdfBandSlice bare = esdfBandSlice(map, c);
  EXPECT_TRUE(bare.stats.padding_cut);
  EXPECT_EQ(bare.stats.padding_voxels, 0u);
  EXPECT_EQ(bare.stats.columns_computed, 400u);
}

TEST(SliceWindow, BandEsdfRefusesAGridOffTheLattice) {
  RoomScene scene;
  const TsdfMap map = filledRoom(0.05, scene);
  EsdfBandConfig c;
  c.grid = GridGeometry(10, 10, 0.05, 0.0, 0.0);  // cell centres between voxel centres
  EXPECT_FALSE(c.validate(map.voxelSize()).empty());
  EXPECT_THROW(esdfBandSlice(map, c), std::invalid_argument);
  c.grid = GridGeometry(10, 10, 0.1, -0.025, -0.025);  // two voxels a cell
  EXPECT_THROW(esdfBandSlice(map, c), std::invalid_argument);
  c.grid = GridGeometry(10, 10, 0.05, -0.025, 0.475);  // on it
  EXPECT_TRUE(c.validate(map.voxelSize()).empty());
  EXPECT_EQ(esdfBandSlice(map, c).grid, *c.grid);
  c.grid = GridGeometry();  // an empty window: no cells, nothing computed
  const EsdfBandSlice none = esdfBandSlice(map, c);
  EXPECT_TRUE(none.distance_m.empty());
  EXPECT_EQ(none.stats.columns_computed, 0u);
}
