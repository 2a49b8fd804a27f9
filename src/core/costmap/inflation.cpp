#include "downstream_perception/core/costmap/inflation.h"

#include "downstream_perception/core/grid/grid_shift.h"
#include "downstream_perception/core/parallel/avx2_clones.h"
#include "inflation_detail.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

using inflation_detail::area;
using inflation_detail::grow;
using inflation_detail::kTileShift;

std::string InflationConfig::validate() const {
  std::ostringstream why;
  if (!std::isfinite(inflation_radius) || inflation_radius < 0.0 || inflation_radius > 100.0) {
    why << "inflation_radius must be in [0, 100] m, got " << inflation_radius;
  } else if (!std::isfinite(cost_scaling_factor) || cost_scaling_factor < 0.0) {
    why << "cost_scaling_factor must be finite and >= 0 (1/m), got " << cost_scaling_factor;
  } else if (!std::isfinite(inscribed_radius) || inscribed_radius < 0.0) {
    why << "inscribed_radius must be finite and >= 0 m, got " << inscribed_radius;
  }
  return why.str();
}

std::string InflationConfig::validate(double resolution_m) const {
  std::string why = validate();
  if (!why.empty()) return why;
  std::ostringstream out;
  if (!std::isfinite(resolution_m) || resolution_m <= 0.0) {
    out << "resolution must be finite and > 0 m, got " << resolution_m;
  } else if (inflation_radius / resolution_m > kMaxRadiusCells) {
    // Compared as doubles: the quotient may be far beyond any int (or +inf).
    out << "inflation_radius " << inflation_radius << " m is " << inflation_radius / resolution_m
        << " cells of " << resolution_m << " m, more than the limit of " << kMaxRadiusCells
        << " cells (at most " << kMaxRadiusCells * resolution_m << " m at this resolution)";
  }
  return out.str();
}

namespace {
// A relative tolerance so a cell exactly on the radius counts as inside: 0.55 m is
// 11.000000000000002 cells of 0.05 m in double, and a map's resolution arrives as float32
// (nav_msgs/MapMetaData: 0.1 is 0.100000001490116, so 1.0 m is 9.99999985 cells). 1e-6 is well
// above float32's relative error (6e-8) and far below any real cell fraction.
constexpr double kRadiusTolerance = 1e-6;

constexpr int kCompareChunk = 16;
/// Whether any of kCompareChunk master cells is lethal where `lethal` says not, or the reverse.
inline bool lethalChanged(const std::uint8_t* master, const std::uint8_t* lethal) {
  std::uint8_t diff = 0;
  for (int i = 0; i < kCompareChunk; ++i) {
    diff |= static_cast<std::uint8_t>((master[i] == cost::kLethalObstacle ? 1 : 0) ^ lethal[i]);
  }
  return diff != 0;
}
}  // namespace

std::uint8_t inflationCost(double distance_m, const InflationConfig& config) {
  if (distance_m == 0.0) return cost::kLethalObstacle;
  if (distance_m > config.inflation_radius * (1.0 + kRadiusTolerance) + 1e-12) {
    return cost::kFreeSpace;
  }
  if (distance_m <= config.inscribed_radius * (1.0 + kRadiusTolerance) + 1e-12) {
    return cost::kInscribedInflatedObstacle;
  }
  const double factor =
      std::exp(-config.cost_scaling_factor * (distance_m - config.inscribed_radius));
  return static_cast<std::uint8_t>((cost::kInscribedInflatedObstacle - 1) * factor);
}

double inscribedTieCells(const InflationConfig& config, double resolution_m) {
  const double inscribed = config.inscribed_radius;
  if (!(inscribed > 0.0) || !(resolution_m > 0.0) || !std::isfinite(inscribed)) return 0.0;
  // Only cells next to the circle of the inscribed radius can tie: per column i the rows around
  // sqrt(r^2 - i^2) (r in cells), so O(r) work however large the footprint.
  const double r = std::min(inscribed / resolution_m, double{InflationConfig::kMaxRadiusCells});
  double nearest = 0.0;
  for (int i = 0; i <= static_cast<int>(r) + 1; ++i) {
    const double t = r * r - static_cast<double>(i) * i;
    const int j0 = static_cast<int>(std::sqrt(std::max(t, 0.0)));
    for (int j = std::max(0, j0 - 1); j <= j0 + 1; ++j) {
      const double cells = std::hypot(static_cast<double>(i), static_cast<double>(j));
      const double d = cells * resolution_m;
      if (d == 0.0 || d > config.inflation_radius) continue;
      const bool ours = inflationCost(d, config) == cost::kInscribedInflatedObstacle;
      if (ours != (d <= inscribed) && (nearest == 0.0 || cells < nearest)) nearest = cells;
    }
  }
  return nearest;
}

void boundedSquaredDistances(const std::uint8_t* lethal, int stride, const CellBounds& source_box,
                             const CellBounds& out_box, int max_distance_cells,
                             std::vector<std::int32_t>* out) {
  const int sw = source_box.max_x - source_box.min_x + 1;
  const int ow = out_box.max_x - out_box.min_x + 1;
  const int oh = out_box.max_y - out_box.min_y + 1;
  out->assign(static_cast<std::size_t>(ow) * static_cast<std::size_t>(oh), kFarSquared);
  if (sw <= 0 || ow <= 0 || oh <= 0) return;
  const int far = max_distance_cells + 1;  // "no lethal cell within the radius in this column"

  // Pass 1 (columns, swept row by row so memory is read in order): vertical distance to the
  // nearest lethal cell in the same column, capped at `far`.
  std::vector<std::int32_t> vertical(static_cast<std::size_t>(sw) * oh, far);
  std::vector<std::int32_t> run(sw, far);
  for (int y = source_box.min_y; y <= source_box.max_y; ++y) {
    const std::uint8_t* row = lethal + static_cast<std::size_t>(y) * stride + source_box.min_x;
    for (int i = 0; i < sw; ++i) run[i] = row[i] ? 0 : std::min(run[i] + 1, far);
    if (y >= out_box.min_y && y <= out_box.max_y) {
      std::copy(run.begin(), run.end(),
                vertical.begin() + static_cast<std::size_t>(y - out_box.min_y) * sw);
    }
  }
  std::fill(run.begin(), run.end(), far);
  for (int y = source_box.max_y; y >= source_box.min_y; --y) {
    const std::uint8_t* row = lethal + static_cast<std::size_t>(y) * stride + source_box.min_x;
    for (int i = 0; i < sw; ++i) run[i] = row[i] ? 0 : std::min(run[i] + 1, far);
    if (y >= out_box.min_y && y <= out_box.max_y) {
      std::int32_t* v = vertical.data() + static_cast<std::size_t>(y - out_box.min_y) * sw;
      for (int i = 0; i < sw; ++i) v[i] = std::min(v[i], run[i]);
    }
  }

  // Pass 2 (rows): d2(x) = min_k (x - k)^2 + vertical(k)^2 over the lower envelope of the
  // parabolas of the columns that have a lethal cell within reach.
  std::vector<int> hull(sw);
  std::vector<double> bound(sw + 1);
  const int x_offset = out_box.min_x - source_box.min_x;  // out column 0 in source coordinates
  for (int r = 0; r < oh; ++r) {
    const std::int32_t* v = vertical.data() + static_cast<std::size_t>(r) * sw;
    const auto f = [v](int k) { return static_cast<std::int64_t>(v[k]) * v[k]; };
    int n = -1;  // index of the last parabola in the hull
    for (int q = 0; q < sw; ++q) {
      if (v[q] >= far) continue;
      double s = -std::numeric_limits<double>::infinity();
      while (n >= 0) {
        const int p = hull[n];
        s = static_cast<double>((f(q) + std::int64_t{q} * q) - (f(p) + std::int64_t{p} * p)) /
            (2.0 * (q - p));
        if (s > bound[n]) break;
        --n;
      }
      ++n;
      hull[n] = q;
      bound[n] = n == 0 ? -std::numeric_limits<double>::infinity() : s;
      bound[n + 1] = std::numeric_limits<double>::infinity();
    }
    if (n < 0) continue;  // the row stays kFarSquared
    std::int32_t* o = out->data() + static_cast<std::size_t>(r) * ow;
    int j = 0;
    for (int x = 0; x < ow; ++x) {
      const int xs = x + x_offset;
      while (bound[j + 1] < xs) ++j;
      const std::int64_t dx = xs - hull[j];
      const std::int64_t d2 = dx * dx + f(hull[j]);
      o[x] = d2 < kFarSquared ? static_cast<std::int32_t>(d2) : kFarSquared;
    }
  }
}

Inflator::Inflator(const InflationConfig& config, double resolution_m) {
  setConfig(config, resolution_m);
}

void Inflator::setConfig(const InflationConfig& config, double resolution_m) {
  const std::string why = config.validate(resolution_m);
  if (!why.empty()) throw std::invalid_argument("inflation: " + why);
  config_ = config;
  resolution_ = resolution_m;
  const double radius = config.inflation_radius / resolution_m;  // cells
  radius_cells_ = static_cast<int>(std::floor(radius * (1.0 + kRadiusTolerance) + 1e-9));
  const auto max_d2 =
      static_cast<std::int64_t>(std::floor(radius * radius * (1.0 + kRadiusTolerance) + 1e-9));
  cost_by_d2_.assign(static_cast<std::size_t>(max_d2) + 1, 0);
  for (std::int64_t d2 = 0; d2 <= max_d2; ++d2) {
    cost_by_d2_[d2] = inflationCost(std::sqrt(static_cast<double>(d2)) * resolution_m, config);
  }
  buildKernel();
  full_recompute_ = true;
}

void Inflator::resizeTo(const GridGeometry& geometry) {
  geometry_ = geometry;
  lethal_.assign(geometry.cellCount(), 0);
  costs_.assign(geometry.cellCount(), 0);
  const int tiles_x = (geometry.sizeX() >> kTileShift) + 1;
  const int tiles_y = (geometry.sizeY() >> kTileShift) + 1;
  dirty_tiles_.assign(static_cast<std::size_t>(tiles_x) * tiles_y, 0);
  dirty_tile_count_ = 0;
  dirty_tile_box_ = CellBounds{};
  pending_regions_.clear();
  full_recompute_ = true;
}

void Inflator::shift(int dx, int dy) {
  if (dx == 0 && dy == 0) return;
  if (full_recompute_ || geometry_.cellCount() == 0) {
    // Nothing cached worth moving: the next update recomputes everything anyway.
    if (geometry_.cellCount() > 0) geometry_ = shiftedGeometry(geometry_, dx, dy);
    return;
  }
  const int nx = geometry_.sizeX();
  const int ny = geometry_.sizeY();
  // 64-bit: std::abs(INT_MIN) is undefined.
  if (std::abs(std::int64_t{dx}) >= nx || std::abs(std::int64_t{dy}) >= ny) {
    geometry_ = shiftedGeometry(geometry_, dx, dy);
    full_recompute_ = true;
    return;
  }
  const GridGeometry shifted = shiftedGeometry(geometry_, dx, dy);  // may throw: nothing moved
  shiftGridData(&lethal_, nx, ny, dx, dy, std::uint8_t{0});
  shiftGridData(&costs_, nx, ny, dx, dy, std::uint8_t{0});
  geometry_ = shifted;
  // Bands still pending from an earlier shift move with the content.
  std::vector<CellBounds> moved;
  for (const CellBounds& b : pending_regions_) {
    const CellBounds m =
        grow({b.min_x - dx, b.min_y - dy, b.max_x - dx, b.max_y - dy}, 0, geometry_);
    if (!m.empty()) moved.push_back(m);
  }
  pending_regions_.swap(moved);
  // Pending marks referred to the old origin: rather than move them, mark their area in the
  // new frame conservatively by recomputing wherever anything was pending.
  if (dirty_tile_count_ > 0) {
    CellBounds pending;
    pending.expand((dirty_tile_box_.min_x << kTileShift) - dx,
                   (dirty_tile_box_.min_y << kTileShift) - dy);
    pending.expand(((dirty_tile_box_.max_x + 1) << kTileShift) - 1 - dx,
                   ((dirty_tile_box_.max_y + 1) << kTileShift) - 1 - dy);
    std::fill(dirty_tiles_.begin(), dirty_tiles_.end(), 0);
    dirty_tile_count_ = 0;
    dirty_tile_box_ = CellBounds{};
    markDirty(pending);
  }
  // Cells that came into view need costs from the lethal cells near them; cells along the edge
  // the map moved away from may have lost lethal cells (now outside) that inflated them. Both
  // are thin bands: recompute them as regions of their own at the next update.
  const int r = radius_cells_;
  const auto band = [&](int x0, int y0, int x1, int y1) {
    pending_regions_.push_back(grow({x0, y0, x1, y1}, 0, geometry_));
  };
  if (dx > 0) {
    band(nx - dx, 0, nx - 1, ny - 1);
    band(0, 0, r, ny - 1);
  } else if (dx < 0) {
    band(0, 0, -dx - 1, ny - 1);
    band(nx - 1 - r, 0, nx - 1, ny - 1);
  }
  if (dy > 0) {
    band(0, ny - dy, nx - 1, ny - 1);
    band(0, 0, nx - 1, r);
  } else if (dy < 0) {
    band(0, 0, nx - 1, -dy - 1);
    band(0, ny - 1 - r, nx - 1, ny - 1);
  }
}

void Inflator::markDirty(const CellBounds& cells) {
  const CellBounds c = grow(cells, 0, geometry_);
  if (c.empty()) return;
  const int tiles_x = (geometry_.sizeX() >> kTileShift) + 1;
  for (int ty = c.min_y >> kTileShift; ty <= (c.max_y >> kTileShift); ++ty) {
    for (int tx = c.min_x >> kTileShift; tx <= (c.max_x >> kTileShift); ++tx) {
      std::uint8_t& tile = dirty_tiles_[static_cast<std::size_t>(ty) * tiles_x + tx];
      if (tile) continue;
      tile = 1;
      ++dirty_tile_count_;
      dirty_tile_box_.expand(tx, ty);
    }
  }
}

bool Inflator::recompute(const CellBounds& region, const GridGeometry& g) {
  return recompute(region, g, &scratch_);
}

bool Inflator::recompute(const CellBounds& region, const GridGeometry& g,
                         std::vector<std::int32_t>* scratch) {
  if (region.empty()) return false;
  const CellBounds sources = grow(region, radius_cells_, g);
  if (stamp_ok_ && method_ != InflationMethod::kTransform) {
    scratch->clear();
    const std::size_t boundary = collectBoundary(sources, g, scratch);
    if (preferStamp(scratch->size() / 3, boundary, area(sources))) {
      stampRegion(scratch->data(), scratch->data() + scratch->size(), region, g, true);
      return true;
    }
  }
  boundedSquaredDistances(lethal_.data(), g.sizeX(), sources, region, radius_cells_, scratch);
  const int w = region.max_x - region.min_x + 1;
  for (int y = region.min_y; y <= region.max_y; ++y) {
    const std::int32_t* d2 = scratch->data() + static_cast<std::size_t>(y - region.min_y) * w;
    std::uint8_t* c = costs_.data() + g.index(region.min_x, y);
    for (int x = 0; x < w; ++x) c[x] = costOfSquaredDistance(d2[x]);
  }
  return false;
}

void Inflator::recomputeDirtyTiles(const GridGeometry& g, InflationStats* stats) {
  if (dirty_tile_count_ == 0) return;
  const int tiles_x = (g.sizeX() >> kTileShift) + 1;
  const auto tileCells = [&](int tx, int ty) {
    CellBounds b;
    b.expand(tx << kTileShift, ty << kTileShift);
    b.expand(((tx + 1) << kTileShift) - 1, ((ty + 1) << kTileShift) - 1);
    return grow(b, radius_cells_, g);  // cells whose distance may have changed
  };
  // One region over all dirty tiles when that is cheaper than one region per tile.
  CellBounds merged = tileCells(dirty_tile_box_.min_x, dirty_tile_box_.min_y);
  merged.expand(tileCells(dirty_tile_box_.max_x, dirty_tile_box_.max_y));
  const std::size_t per_tile =
      dirty_tile_count_ *
      area(grow(tileCells(dirty_tile_box_.min_x, dirty_tile_box_.min_y), radius_cells_, g));
  const bool one_region = area(grow(merged, radius_cells_, g)) <= per_tile;
  for (int ty = dirty_tile_box_.min_y; ty <= dirty_tile_box_.max_y; ++ty) {
    for (int tx = dirty_tile_box_.min_x; tx <= dirty_tile_box_.max_x; ++tx) {
      std::uint8_t& tile = dirty_tiles_[static_cast<std::size_t>(ty) * tiles_x + tx];
      if (!tile) continue;
      tile = 0;
      if (one_region) continue;
      const CellBounds region = tileCells(tx, ty);
      stats->regions_stamped += recompute(region, g) ? 1 : 0;
      ++stats->regions;
      stats->cells_recomputed += area(region);
    }
  }
  if (one_region) {
    stats->regions_stamped = recompute(merged, g) ? 1 : 0;
    stats->regions = 1;
    stats->cells_recomputed = area(merged);
  }
  dirty_tile_count_ = 0;
  dirty_tile_box_ = CellBounds{};
}

// The window's lethal compare and merge vectorise twice as wide with AVX2 (avx2_clones.h).
// Integer compares and selects: both copies give the same bytes.
DP_AVX2_CLONES
InflationStats Inflator::update(Costmap* master, const CellBounds& window) {
  InflationStats stats;
  const GridGeometry& g = master->geometry();
  if (g.cellCount() == 0) return stats;
  if (!(g == geometry_)) resizeTo(g);
  const std::uint8_t* m = master->data();
  const int size_x = g.sizeX();
  const CellBounds w = master->clamp(window);

  if (full_recompute_) {
    recomputeAll(m, g, &stats);
    std::fill(dirty_tiles_.begin(), dirty_tiles_.end(), 0);
    dirty_tile_count_ = 0;
    dirty_tile_box_ = CellBounds{};
    pending_regions_.clear();
    full_recompute_ = false;
  } else {
    for (const CellBounds& region : pending_regions_) {  // edges after a rolling-window shift
      stats.regions_stamped += recompute(region, g) ? 1 : 0;
      ++stats.regions;
      stats.cells_recomputed += area(region);
    }
    pending_regions_.clear();
    // Where did the set of lethal cells change?
    const int tiles_x = (g.sizeX() >> kTileShift) + 1;
    for (int y = w.min_y; !w.empty() && y <= w.max_y; ++y) {
      const std::size_t row = static_cast<std::size_t>(y) * size_x;
      for (int x = w.min_x; x <= w.max_x; ++x) {
        // 16 cells at a time while nothing changed (one vector compare; almost every chunk of
        // a steady map).
        if (x + kCompareChunk <= w.max_x + 1 &&
            !lethalChanged(m + row + x, lethal_.data() + row + x)) {
          x += kCompareChunk - 1;
          continue;
        }
        const std::uint8_t now = m[row + x] == cost::kLethalObstacle ? 1 : 0;
        if (now == lethal_[row + x]) continue;
        lethal_[row + x] = now;
        ++stats.lethal_changed;
        const int tx = x >> kTileShift;
        const int ty = y >> kTileShift;
        std::uint8_t& tile = dirty_tiles_[static_cast<std::size_t>(ty) * tiles_x + tx];
        if (!tile) {
          tile = 1;
          ++dirty_tile_count_;
          dirty_tile_box_.expand(tx, ty);
        }
      }
    }
    recomputeDirtyTiles(g, &stats);
  }

  // Merge into the master over the window (costmap_2d's InflationLayer rule).
  if (w.empty()) return stats;
  std::uint8_t* out = master->data();
  const std::uint8_t unknown_threshold =
      config_.inflate_unknown ? std::uint8_t{1} : cost::kInscribedInflatedObstacle;
  const int width = w.max_x - w.min_x + 1;
  for (int y = w.min_y; y <= w.max_y; ++y) {
    const std::size_t row = g.index(w.min_x, y);
    std::uint8_t* dst = out + row;
    const std::uint8_t* src = costs_.data() + row;
    for (int x = 0; x < width; ++x) {
      const std::uint8_t old = dst[x];
      const std::uint8_t c = src[x];
      const std::uint8_t merged =
          old == cost::kNoInformation ? (c >= unknown_threshold ? c : old) : std::max(old, c);
      dst[x] = merged;
    }
  }
  stats.cells_merged = area(w);
  return stats;
}

}  // namespace downstream_perception
