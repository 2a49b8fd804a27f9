// The full recompute of the inflation cache (start-up, new parameters, a resized map), restricted
// to the band within the inflation radius of lethal cells (issue 20).
//
// The distance transform of the whole map cost O(map) whatever the radius (12 ms on 1000^2),
// although only cells within the radius of a lethal cell can get a cost. Here the map is cut into
// horizontal strips of whole 32-cell tiles; in each strip, the tile columns within reach of a tile
// holding a lethal cell form runs, and each run is one region of the exact bounded transform that
// the incremental updates already use (Inflator::recompute: sources grown by the radius), so every
// cell of a region gets exactly the cost the whole-map transform gave it. Every other cell has no
// lethal cell within the radius and gets the cost of "far". A strip is at least 4 radii high, so
// the sources a region reads beyond its own rows (one radius above and below) cost at most half
// again. The regions are disjoint, so they split over two threads with no effect on the result.
// Where lethal cells are sparse enough, stampAll (inflation_stamp.cpp) replaces all of this.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "downstream_perception/core/costmap/inflation.h"
#include "downstream_perception/core/parallel/avx2_clones.h"
#include "inflation_detail.h"

namespace downstream_perception {

using inflation_detail::area;
using inflation_detail::grow;
using inflation_detail::kTileShift;

namespace {

constexpr int kTile = 1 << kTileShift;
/// Below this many cells to recompute, a second thread costs more than it saves.
constexpr std::size_t kThreadMinCells = 150000;

}  // namespace

std::vector<CellBounds> Inflator::bandRegions(const GridGeometry& g,
                                              const std::vector<std::uint8_t>& lethal_tiles,
                                              int tiles_x, int tiles_y) const {
  // A cell within radius_cells_ of a lethal cell lies at most ceil(radius / 32) tiles away from
  // the lethal cell's tile along each axis.
  const int reach = (radius_cells_ + kTile - 1) / kTile;
  const int strip_tiles = std::max(1, (4 * radius_cells_ + kTile - 1) / kTile);
  std::vector<std::uint8_t> column(tiles_x);
  std::vector<std::uint8_t> band(tiles_x);
  std::vector<CellBounds> regions;
  for (int ty0 = 0; ty0 < tiles_y; ty0 += strip_tiles) {
    const int ty1 = std::min(ty0 + strip_tiles, tiles_y) - 1;
    const int y0 = ty0 * kTile;
    const int y1 = std::min((ty1 + 1) * kTile, g.sizeY()) - 1;
    if (y0 > y1) break;  // the last tile row can lie past the map (tiles_y rounds up)
    // Tile columns holding a lethal cell within reach rows of the strip ...
    std::fill(column.begin(), column.end(), 0);
    for (int ty = std::max(0, ty0 - reach); ty <= std::min(tiles_y - 1, ty1 + reach); ++ty) {
      const std::uint8_t* row = lethal_tiles.data() + static_cast<std::size_t>(ty) * tiles_x;
      for (int tx = 0; tx < tiles_x; ++tx) column[tx] |= row[tx];
    }
    // ... grown by reach columns: the strip's tiles where a cost may be non-zero.
    std::fill(band.begin(), band.end(), 0);
    for (int tx = 0; tx < tiles_x; ++tx) {
      if (!column[tx]) continue;
      for (int k = std::max(0, tx - reach); k <= std::min(tiles_x - 1, tx + reach); ++k)
        band[k] = 1;
    }
    for (int tx = 0; tx < tiles_x;) {
      if (!band[tx]) {
        ++tx;
        continue;
      }
      const int start = tx;
      while (tx < tiles_x && band[tx]) ++tx;
      CellBounds r;
      r.min_x = start * kTile;
      r.max_x = std::min(tx * kTile, g.sizeX()) - 1;
      r.min_y = y0;
      r.max_y = y1;
      if (!r.empty()) regions.push_back(r);
    }
  }
  return regions;
}

// The pass over the master (lethal set, starting costs) vectorises twice as wide with AVX2
// (avx2_clones.h).
DP_AVX2_CLONES
void Inflator::recomputeAll(const std::uint8_t* master, const GridGeometry& g,
                            InflationStats* stats) {
  const int size_x = g.sizeX();
  const int size_y = g.sizeY();
  const int tiles_x = (size_x >> kTileShift) + 1;
  const int tiles_y = (size_y >> kTileShift) + 1;
  std::vector<std::uint8_t> lethal_tiles(static_cast<std::size_t>(tiles_x) * tiles_y, 0);
  // One pass over the master: the lethal set, and the costs every cell starts from (254 on a
  // lethal cell, the cost of "far" = 0 elsewhere; regions overwrite theirs).
  for (int y = 0; y < size_y; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * size_x;
    const std::uint8_t* m = master + row;
    std::uint8_t* l = lethal_.data() + row;
    std::uint8_t* c = costs_.data() + row;
    for (int x = 0; x < size_x; ++x) {
      const bool lethal = m[x] == cost::kLethalObstacle;
      l[x] = lethal ? 1 : 0;
      c[x] = lethal ? cost::kLethalObstacle : std::uint8_t{0};
    }
    std::uint8_t* tiles = lethal_tiles.data() + static_cast<std::size_t>(y >> kTileShift) * tiles_x;
    for (int x0 = 0; x0 < size_x; x0 += kTile) {
      std::uint8_t& tile = tiles[x0 >> kTileShift];
      if (tile) continue;
      // OR of 8-byte words (a byte loop with an early exit does not vectorise: it was most of
      // this pass).
      const int x1 = std::min(x0 + kTile, size_x);
      std::uint64_t any = 0;
      int x = x0;
      for (; x + 8 <= x1; x += 8) {
        std::uint64_t word;
        std::memcpy(&word, l + x, sizeof(word));
        any |= word;
      }
      for (; x < x1; ++x) any |= l[x];
      tile = any != 0 ? 1 : 0;
    }
  }
  static_assert(cost::kFreeSpace == 0, "cells out of reach start at the cost of far, 0");
  const std::vector<CellBounds> regions = bandRegions(g, lethal_tiles, tiles_x, tiles_y);
  std::size_t band_sources = 0;  // what the transform would read
  for (const CellBounds& r : regions) band_sources += area(grow(r, radius_cells_, g));
  if (stampAll(g, band_sources, stats)) return;  // sparse lethal cells: no transform at all
  std::size_t cells = 0;
  for (const CellBounds& r : regions) cells += area(r);
  stats->regions = regions.size();
  stats->cells_recomputed = cells;
  if (threads_ < 2 || cells < kThreadMinCells || regions.size() < 2) {
    for (const CellBounds& r : regions) stats->regions_stamped += recompute(r, g, &scratch_);
    return;
  }
  // Two halves of about equal area, the second on a worker thread (each with its own scratch).
  std::size_t first_cells = 0;
  std::size_t split = 0;
  while (split < regions.size() && 2 * first_cells < cells) first_cells += area(regions[split++]);
  std::size_t stamped_by_worker = 0;
  std::thread worker([&] {
    std::vector<std::int32_t> scratch;
    for (std::size_t i = split; i < regions.size(); ++i) {
      stamped_by_worker += recompute(regions[i], g, &scratch) ? 1 : 0;
    }
  });
  for (std::size_t i = 0; i < split; ++i)
    stats->regions_stamped += recompute(regions[i], g, &scratch_);
  worker.join();
  stats->regions_stamped += stamped_by_worker;
}

}  // namespace downstream_perception
