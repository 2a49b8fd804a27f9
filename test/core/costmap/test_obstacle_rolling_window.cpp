// The rolling-window wall of issue 18 item 4: a wall face on a cell edge stays one cell thick
// while the obstacle layer's window follows the robot (beams -> scan integrator -> log-odds
// grid).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "downstream_perception/core/costmap/scan_integrator.h"

using namespace downstream_perception;  // NOLINT

namespace {

struct WallDrive {
  double res;
  double wall;    // the wall face's x (m), on a cell edge of the starting lattice
  double robot0;  // the robot's start x (m): < wall sees the wall's near face from -x
  double step_x;  // robot motion per update (m)
  double step_y;
  bool transpose;  // the same with x and y swapped (a wall face at y = wall)
};

// A robot drives past a wall in a rolling window (shifted by whole cells as LayeredCostmap does:
// the window centred on the robot, rounded to cells), seeing the wall face as exact points (a
// point cloud on a lattice, a simulated wall). Returns the occupied cells that are not the wall
// face's own world cells (those containing the points); *on_wall counts those that are.
std::size_t thickCells(const WallDrive& w, int updates, std::size_t* on_wall) {
  const int size = static_cast<int>(std::lround(4.0 / w.res));  // a 4 m window
  const double half = 0.5 * size * w.res;
  const GridGeometry g0(size, size, w.res, -2.0, -2.0);
  LogOddsGrid grid(g0);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 3.0;
  config.raytrace_max_range = 3.5;
  ScanIntegrator integrator(config);
  // The wall face's world cell column (or row), counted on the starting lattice.
  const std::int64_t wall_cell = g0.worldToCellUnbounded(w.wall, w.wall).x;
  std::int64_t shift_x = 0;
  std::int64_t shift_y = 0;
  double along_wall = 0.0;   // the robot's position along the wall
  double across = w.robot0;  // and across it
  std::vector<BeamUpdate> beams;
  for (int u = 0; u < updates; ++u) {
    across += w.step_x;
    along_wall += w.step_y;
    const double rx = w.transpose ? along_wall : across;
    const double ry = w.transpose ? across : along_wall;
    // Rolling: keep the robot at the window's centre, in whole cells.
    const GridGeometry& g = grid.geometry();
    const int dx = static_cast<int>(std::lround((rx - half - g.originX()) / w.res));
    const int dy = static_cast<int>(std::lround((ry - half - g.originY()) / w.res));
    grid.shift(dx, dy);
    shift_x += dx;
    shift_y += dy;
    // The wall face: points every third of a cell along it, 2 m either side of the robot.
    beams.clear();
    IntegrationStats decisions;
    for (int k = -120; k <= 120; ++k) {
      const double p = along_wall + k * (w.res / 3);
      const double px = w.transpose ? p : w.wall;
      const double py = w.transpose ? w.wall : p;
      integrator.beamToPoint(rx, ry, px, py, 0.0, 1e4, &beams, &decisions);
    }
    integrator.integrate(grid, beams, decisions);
  }
  std::size_t thick = 0;
  *on_wall = 0;
  const GridGeometry& g = grid.geometry();
  for (int y = 0; y < g.sizeY(); ++y) {
    for (int x = 0; x < g.sizeX(); ++x) {
      if (grid.state(g.index(x, y)) != CellState::kOccupied) continue;
      const std::int64_t cell = w.transpose ? y + shift_y : x + shift_x;
      thick += cell != wall_cell;
      *on_wall += cell == wall_cell;
    }
  }
  return thick;
}

}  // namespace

// Issue 18 item 4 (c): a wall face exactly on a cell edge stays one cell thick in a rolling
// window. costmap_2d's worldToMap counts from the moved origin, so the face's points fall on one
// side of the edge after some shifts and on the other after others; our grid counts cells on
// the lattice it started on (and a cloud point's hit is the point itself, and the ray ends in the
// cell the hit marks), so the face is in one world cell for good. From either side, along and
// across the wall, at several resolutions and with x and y swapped.
TEST(ObstacleParity, RollingWindowKeepsAnEdgeAlignedWallOneCellThick) {
  for (const double res : {0.05, 0.1, 0.025}) {
    const double wall = -2.0 + 64 * res;  // on an edge of the starting lattice
    for (const bool transpose : {false, true}) {
      const std::vector<WallDrive> drives = {
          {res, wall, wall - 1.0, 0.0, 0.013, transpose},    // along it, facing it from -x
          {res, wall, wall + 1.0, 0.0, -0.017, transpose},   // along it, from +x
          {res, wall, wall - 2.5, 0.011, 0.007, transpose},  // approaching it
          {res, wall, wall + 2.5, -0.009, 0.012, transpose},
      };
      for (const WallDrive& d : drives) {
        std::size_t on_wall = 0;
        const std::string what = "res " + std::to_string(res) + " robot from " +
                                 std::to_string(d.robot0) + " step " + std::to_string(d.step_x) +
                                 "," + std::to_string(d.step_y) +
                                 (transpose ? " (transposed)" : "");
        EXPECT_EQ(thickCells(d, 150, &on_wall), 0u) << what;
        EXPECT_GT(on_wall, 20u) << what;  // the face itself is there
      }
    }
  }
}
