// Inflation: cost of a cell from its exact Euclidean distance to the nearest LETHAL cell, with
// costmap_2d's formula, kept up to date incrementally.
//
//   d = 0                       -> LETHAL_OBSTACLE (254)
//   0 < d <= inscribed_radius   -> INSCRIBED_INFLATED_OBSTACLE (253)
//   d <= inflation_radius       -> floor(252 * exp(-cost_scaling_factor * (d - inscribed_radius)))
//   d > inflation_radius        -> 0
//
// Distances are exact: squared cell distances are integers, computed by a separable lower-envelope
// distance transform (Felzenszwalb & Huttenlocher) bounded to the inflation radius, and the cost
// comes from a table indexed by the squared distance, so there is no floating-point rounding
// between the distance and its cost. (costmap_2d's wavefront approximates the nearest source and
// is off in about 1 cell in 16,000; a full OpenCV distance transform would be exact too, but costs
// O(map) per update and float distances.)
//
// Two exact ways to the same costs (src/core/costmap/inflation_stamp.cpp): where lethal cells
// are sparse, each lethal cell on the boundary of the lethal set stamps a precomputed disc of
// costs with max(); the cost only falls with distance, so the max over the stamps is the cost of
// the nearest lethal cell, bit for bit what the transform gives. Where lethal cells are dense the
// transform is cheaper; a cost estimate picks per region (InflationMethod::kAuto).
//
// Incremental: the Inflator keeps the set of lethal cells it last saw and the inflation costs
// they produce. Each update compares the master's lethal cells inside the update window with that
// set; only cells within the inflation radius of a changed lethal cell are recomputed (from the
// lethal cells within the radius of those), then the cached costs are merged into the master over
// the window. A sensor sweeping an unchanged room costs a compare and a merge, no distance
// transform.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "downstream_perception/core/grid/costmap.h"

namespace downstream_perception {

struct InflationConfig {
  /// Largest inflation radius in cells (inflation_radius / resolution): 2000 cells, 100 m at
  /// 5 cm, 20 m at 1 cm. The cost table has radius^2 entries and each update recomputes up to the
  /// radius around every change: at 2000 cells a full update of a 4000^2 map takes ~0.4 s, while
  /// 0.55 m at 2e-5 m (27,500 cells) took 28 s per update, and 5e-324 m could not even allocate.
  static constexpr int kMaxRadiusCells = 2000;

  double inflation_radius = 0.55;     ///< m: cells farther than this from any lethal cell get 0
  double cost_scaling_factor = 10.0;  ///< 1/m: exponential decay rate beyond the inscribed radius
  double inscribed_radius = 0.0;      ///< m: from the footprint; cells this close get 253
  bool inflate_unknown = false;  ///< write inflated costs over NO_INFORMATION cells (costmap_2d)

  /// Empty if valid, else a message naming the offending field and value.
  std::string validate() const;
  /// Same, and for a costmap of `resolution_m`: the resolution finite and > 0, and the radius at
  /// most kMaxRadiusCells cells.
  std::string validate(double resolution_m) const;
};

/// costmap_2d's cost for a cell at `distance_m` from the nearest lethal cell.
std::uint8_t inflationCost(double distance_m, const InflationConfig& config);

/// The distance (cells, > 0) of the nearest cell within the inflation radius whose cost differs
/// from costmap_2d's only by the inscribed tie, else 0. costmap_2d calls a cell inscribed when
/// hypot(dx, dy) * resolution <= inscribed radius in plain doubles, so a cell exactly at the
/// radius goes either way with the rounding (6 * 0.05 = 0.30000000000000004 > 0.3); inflationCost
/// counts it (1e-6 relative tolerance). For the layer's once-only WARN.
double inscribedTieCells(const InflationConfig& config, double resolution_m);

/// Squared distances (cells^2) from every cell of `out_box` to the nearest cell with
/// lethal[y * stride + x] != 0 among the cells of `source_box`, capped: values above
/// max_distance_cells^2 come out as kFarSquared. out_box must lie inside source_box.
/// `out` has out_box's width as its row stride.
constexpr std::int32_t kFarSquared = 0x3fffffff;
void boundedSquaredDistances(const std::uint8_t* lethal, int stride, const CellBounds& source_box,
                             const CellBounds& out_box, int max_distance_cells,
                             std::vector<std::int32_t>* out);

/// How the Inflator computes a region's costs; both are exact and give the same bytes.
enum class InflationMethod {
  kAuto,       ///< per region, whichever the cost estimate says is cheaper
  kStamp,      ///< max-stamp a cost disc per boundary lethal cell (if the table allows it)
  kTransform,  ///< the bounded distance transform
};

struct InflationStats {
  std::size_t lethal_changed = 0;    ///< cells that became or stopped being lethal
  std::size_t cells_recomputed = 0;  ///< cells whose distance was recomputed
  std::size_t regions = 0;           ///< distance-transform regions run
  std::size_t cells_merged = 0;      ///< cells merged into the master
  std::size_t regions_stamped = 0;   ///< regions computed by stamping (the rest: transform)
};

class Inflator {
 public:
  /// Throws std::invalid_argument if config.validate(resolution_m) fails.
  Inflator(const InflationConfig& config, double resolution_m);

  const InflationConfig& config() const { return config_; }
  /// New parameters (or resolution): the next update recomputes the whole map. Throws
  /// std::invalid_argument (and keeps the old ones) if config.validate(resolution_m) fails.
  void setConfig(const InflationConfig& config, double resolution_m);
  /// Forget the cache: the next update recomputes the whole map.
  void reset() { full_recompute_ = true; }
  /// Rolling window: the master's origin moved by (dx, dy) whole cells. The cache moves with it;
  /// the next update recomputes only near the edges (cells that came into view, and cells that
  /// lost lethal sources which left the map), not the whole map.
  void shift(int dx, int dy);

  /// Inflation radius in whole cells (cells up to this distance may get a cost).
  int radiusCells() const { return radius_cells_; }
  /// Cost for a squared cell distance (the table the update uses).
  std::uint8_t costOfSquaredDistance(std::int64_t d2) const {
    return d2 < static_cast<std::int64_t>(cost_by_d2_.size()) ? cost_by_d2_[d2] : 0;
  }

  /// Brings the cache up to date with the master's lethal cells inside `window` (inclusive;
  /// clamped) and merges the inflation costs into the master over the window with costmap_2d's
  /// rule: max(old, cost), except that a NO_INFORMATION cell takes the cost only if it is
  /// >= INSCRIBED (or > 0 with inflate_unknown). The caller must have grown the window by the
  /// inflation radius around every place where lethal cells may have changed (updateBounds).
  InflationStats update(Costmap* master, const CellBounds& window);

  /// Threads for a full recompute (1 or 2; default 2 where the machine has them): the band's
  /// regions, or the map's two row halves when stamping, split between them, with the same costs
  /// bit for bit. Only large recomputes use the second thread (a scanned 1000^2 room does not).
  void setThreads(int threads) { threads_ = std::max(1, std::min(2, threads)); }
  int threads() const { return threads_; }

  /// Forces one way of computing costs (tests, benchmarks); kAuto by default. kStamp falls back to
  /// the transform when the cost table is not monotone or the radius exceeds kMaxStampRadiusCells.
  void setMethod(InflationMethod method) { method_ = method; }
  InflationMethod method() const { return method_; }
  /// Largest radius (cells) with a stamp kernel: (2r + 1)^2 bytes, 263 kB at 256.
  static constexpr int kMaxStampRadiusCells = 256;

  /// Cached inflation cost per cell (as if no cell were unknown), for tests and Python.
  const std::vector<std::uint8_t>& costs() const { return costs_; }

 private:
  void resizeTo(const GridGeometry& geometry);
  bool recompute(const CellBounds& region, const GridGeometry& geometry);
  /// Returns true if the region was stamped (false: transform).
  bool recompute(const CellBounds& region, const GridGeometry& geometry,
                 std::vector<std::int32_t>* scratch);
  /// The stamp kernel from the cost table (inflation_stamp.cpp); stamp_ok_ false if the table is
  /// not non-increasing in the distance or the radius is too large.
  void buildKernel();
  /// Appends every lethal cell in `box` with a non-lethal 4-neighbour in the map (only those can
  /// be the nearest lethal cell of a non-lethal cell) as runs (x0, x1, y) of consecutive such
  /// cells in a row, in row order; returns the number of cells.
  std::size_t collectBoundary(const CellBounds& box, const GridGeometry& geometry,
                              std::vector<std::int32_t>* runs) const;
  /// Estimated cost of stamping `runs` runs of `boundary_cells` cells vs transforming
  /// `source_cells`: true if stamping is the cheaper (or forced).
  bool preferStamp(std::size_t runs, std::size_t boundary_cells, std::size_t source_cells) const;
  /// costs_ over `clip` = lethal ? 254 : 0 (if `init`; else the caller did that), then
  /// max-stamps the kernel over the runs [begin, end) of a (x0, x1, y) list.
  void stampRegion(const std::int32_t* begin, const std::int32_t* end, const CellBounds& clip,
                   const GridGeometry& geometry, bool init);
  /// One kernel row `krow` stamped around column cx (half width hw) into the cost row `crow`,
  /// clipped to `clip`'s columns.
  void stampRow(const std::uint8_t* krow, std::uint8_t* crow, int cx, int hw,
                const CellBounds& clip) const;
  /// The full recompute by stamping (costs_ already lethal ? 254 : 0), rows split over threads_;
  /// false if transforming `transform_cells` source cells would be cheaper.
  bool stampAll(const GridGeometry& geometry, std::size_t transform_cells, InflationStats* stats);
  /// The whole cache from the master: lethal cells, then the band within the radius of them
  /// (src/core/costmap/inflation_band.cpp).
  void recomputeAll(const std::uint8_t* master, const GridGeometry& geometry,
                    InflationStats* stats);
  /// The band's regions: runs of tiles within reach of a tile holding a lethal cell, per strip.
  std::vector<CellBounds> bandRegions(const GridGeometry& geometry,
                                      const std::vector<std::uint8_t>& lethal_tiles, int tiles_x,
                                      int tiles_y) const;
  /// Marks the tiles covering `cells` (clamped) for recomputation at the next update.
  void markDirty(const CellBounds& cells);
  /// Recomputes every dirty tile's neighbourhood and clears the marks.
  void recomputeDirtyTiles(const GridGeometry& geometry, InflationStats* stats);

  InflationConfig config_;
  double resolution_ = 0.0;
  int radius_cells_ = 0;
  std::vector<std::uint8_t> cost_by_d2_;  ///< cost for squared distance 0 .. radius^2
  std::vector<std::uint8_t> kernel_;  ///< (2r+1) rows of costs around a lethal cell, zero-padded
  /// Bytes per kernel row: 2r+1 costs and 16 zeros, so a stamp can read whole 16-byte chunks.
  std::size_t kernelStride() const { return static_cast<std::size_t>(2 * radius_cells_ + 17); }
  std::vector<int> kernel_half_width_;  ///< per kernel row: largest |dx| with a cost > 0, or -1
  std::size_t stamp_ops_ = 0;           ///< estimated work of one stamp (vector ops + rows)
  bool stamp_ok_ = false;
  InflationMethod method_ = InflationMethod::kAuto;
  GridGeometry geometry_;
  std::vector<std::uint8_t> lethal_;  ///< 1 where the master was lethal at the last update
  std::vector<std::uint8_t> costs_;
  std::vector<std::uint8_t> dirty_tiles_;
  std::size_t dirty_tile_count_ = 0;
  CellBounds dirty_tile_box_;                ///< in tiles
  std::vector<CellBounds> pending_regions_;  ///< bands to recompute after a shift
  std::vector<std::int32_t> scratch_;
  bool full_recompute_ = true;
  int threads_ = std::thread::hardware_concurrency() >= 2 ? 2 : 1;
};

}  // namespace downstream_perception
