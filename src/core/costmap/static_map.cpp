#include "downstream_perception/core/costmap/static_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "downstream_perception/core/grid/cost_values.h"

namespace downstream_perception {

int clampedLethalThreshold(int lethal_cost_threshold) {
  return std::max(std::min(lethal_cost_threshold, 100), 0);
}

std::uint8_t interpretStaticValue(std::uint8_t value, const StaticMapConfig& config) {
  // costmap_2d holds both thresholds in unsigned chars: -1 becomes 255, like the grid's -1.
  const auto unknown = static_cast<std::uint8_t>(config.unknown_cost_value);
  const auto lethal =
      static_cast<std::uint8_t>(clampedLethalThreshold(config.lethal_cost_threshold));
  if (value == unknown) {
    return config.track_unknown_space ? cost::kNoInformation : cost::kFreeSpace;
  }
  if (value >= lethal) return cost::kLethalObstacle;  // lethal 0 makes every known cell lethal
  if (config.trinary_costmap) return cost::kFreeSpace;
  const double scale = static_cast<double>(value) / lethal;  // lethal > value >= 0 here
  return static_cast<std::uint8_t>(scale * cost::kLethalObstacle);
}

std::array<std::uint8_t, 256> staticValueTable(const StaticMapConfig& config) {
  std::array<std::uint8_t, 256> table{};
  for (int v = 0; v < 256; ++v) {
    table[v] = interpretStaticValue(static_cast<std::uint8_t>(v), config);
  }
  return table;
}

std::string validateStaticMap(const StaticMapInfo& info, std::size_t max_cells) {
  std::ostringstream why;
  const bool finite_origin =
      std::isfinite(info.origin_x) && std::isfinite(info.origin_y) && std::isfinite(info.origin_z);
  const bool finite_q = std::isfinite(info.qx) && std::isfinite(info.qy) &&
                        std::isfinite(info.qz) && std::isfinite(info.qw);
  // An all-zero quaternion is a publisher that never set it (geometry_msgs' default): identity.
  const bool unset_q = info.qx == 0.0 && info.qy == 0.0 && info.qz == 0.0 && info.qw == 0.0;
  const double vec = std::sqrt(info.qx * info.qx + info.qy * info.qy + info.qz * info.qz);
  const double angle_rad = finite_q ? 2.0 * std::atan2(vec, std::abs(info.qw)) : 0.0;
  if (info.width <= 0 || info.height <= 0) {
    why << "map size must be positive, got " << info.width << " x " << info.height << " cells";
  } else if (info.width > GridGeometry::kMaxCellsPerAxis ||
             info.height > GridGeometry::kMaxCellsPerAxis ||
             static_cast<std::uint64_t>(info.width) * static_cast<std::uint64_t>(info.height) >
                 max_cells) {
    why << "map of " << info.width << " x " << info.height << " cells exceeds max_cells "
        << max_cells;
  } else if (static_cast<std::uint64_t>(info.width) * static_cast<std::uint64_t>(info.height) !=
             info.data_size) {
    why << "data has " << info.data_size << " values, width x height = " << info.width << " x "
        << info.height;
  } else if (!(std::isfinite(info.resolution) && info.resolution > 0.0 &&
               info.resolution <= GridGeometry::kMaxResolutionM)) {
    why << "resolution must be in (0, " << GridGeometry::kMaxResolutionM << "] m, got "
        << info.resolution;
  } else if (!finite_origin) {
    why << "origin must be finite, got (" << info.origin_x << ", " << info.origin_y << ", "
        << info.origin_z << ")";
  } else if (!finite_q || (!unset_q && angle_rad > 1e-6)) {
    why << "map origin is rotated (quaternion " << info.qx << ", " << info.qy << ", " << info.qz
        << ", " << info.qw << "): rotated maps are not supported";
  }
  return why.str();
}

Affine2D invert(const Affine2D& a) {
  const double det = a.xx * a.yy - a.xy * a.yx;
  Affine2D r;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) {
    const double nan = std::nan("");
    r.xx = r.xy = r.yx = r.yy = r.tx = r.ty = nan;
    return r;
  }
  r.xx = a.yy / det, r.xy = -a.xy / det, r.yx = -a.yx / det, r.yy = a.xx / det;
  r.tx = -(r.xx * a.tx + r.xy * a.ty);
  r.ty = -(r.yx * a.tx + r.yy * a.ty);
  return r;
}

StaticMap::StaticMap(const StaticMapConfig& config)
    : config_(config), table_(staticValueTable(config)), costs_() {}

void StaticMap::countWindow(const CellBounds& window, int sign) {
  StaticCellCounts c;
  for (int y = window.min_y; y <= window.max_y; ++y) {
    const std::uint8_t* row = costs_.data() + costs_.geometry().index(window.min_x, y);
    for (int x = 0; x <= window.max_x - window.min_x; ++x) {
      switch (row[x]) {
        case cost::kLethalObstacle:
          ++c.lethal;
          break;
        case cost::kNoInformation:
          ++c.unknown;
          break;
        case cost::kFreeSpace:
          ++c.free;
          break;
        default:
          ++c.other;
          break;
      }
    }
  }
  if (sign > 0) {
    counts_.lethal += c.lethal, counts_.unknown += c.unknown, counts_.free += c.free,
        counts_.other += c.other;
  } else {
    counts_.lethal -= c.lethal, counts_.unknown -= c.unknown, counts_.free -= c.free,
        counts_.other -= c.other;
  }
}

std::string StaticMap::setMap(const StaticMapInfo& info, const std::int8_t* data) {
  std::string why = validateStaticMap(info, config_.max_cells);
  if (why.empty() && data == nullptr) why = "no data";
  if (why.empty()) {
    why = GridGeometry::validate(static_cast<int>(info.width), static_cast<int>(info.height),
                                 info.resolution, info.origin_x, info.origin_y);
  }
  if (!why.empty()) return why;
  costs_.resize(GridGeometry(static_cast<int>(info.width), static_cast<int>(info.height),
                             info.resolution, info.origin_x, info.origin_y));
  std::uint8_t* out = costs_.data();
  const std::size_t n = costs_.geometry().cellCount();
  for (std::size_t k = 0; k < n; ++k) out[k] = table_[static_cast<std::uint8_t>(data[k])];
  has_map_ = true;
  last_change_ = CellBounds{};
  last_change_.expand(0, 0);
  last_change_.expand(costs_.geometry().sizeX() - 1, costs_.geometry().sizeY() - 1);
  counts_ = StaticCellCounts{};
  countWindow(last_change_, +1);
  return "";
}

std::string StaticMap::applyUpdate(std::int64_t x, std::int64_t y, std::int64_t width,
                                   std::int64_t height, const std::int8_t* data,
                                   std::size_t data_size) {
  std::ostringstream why;
  if (!has_map_) {
    why << "no map yet";
    return why.str();
  }
  const std::int64_t map_w = costs_.geometry().sizeX();
  const std::int64_t map_h = costs_.geometry().sizeY();
  // Every operand is below 2^33 once the sign checks pass: no 64-bit overflow.
  if (width < 0 || height < 0 || width > map_w || height > map_h) {
    why << "update of " << width << " x " << height << " cells does not fit the " << map_w << " x "
        << map_h << " map";
  } else if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) != data_size) {
    why << "update data has " << data_size << " values, width x height = " << width << " x "
        << height;
  } else if (x < 0 || y < 0 || x + width > map_w || y + height > map_h) {
    why << "update window [" << x << ", " << x + width << ") x [" << y << ", " << y + height
        << ") is outside the " << map_w << " x " << map_h << " map";
  } else if (data_size > 0 && data == nullptr) {
    why << "no data";
  }
  if (!why.str().empty()) return why.str();
  last_change_ = CellBounds{};
  if (width == 0 || height == 0) return "";  // a valid, empty update: nothing changes
  CellBounds window;
  window.expand(static_cast<int>(x), static_cast<int>(y));
  window.expand(static_cast<int>(x + width - 1), static_cast<int>(y + height - 1));
  countWindow(window, -1);
  for (std::int64_t r = 0; r < height; ++r) {
    std::uint8_t* row =
        costs_.data() + costs_.geometry().index(static_cast<int>(x), static_cast<int>(y + r));
    const std::int8_t* in = data + r * width;
    for (std::int64_t c = 0; c < width; ++c) row[c] = table_[static_cast<std::uint8_t>(in[c])];
  }
  countWindow(window, +1);
  last_change_ = window;
  return "";
}

namespace {

/// The window [min_i, max_i) x [min_j, max_j) clamped to both grids, as an inclusive CellBounds.
CellBounds clampedWindow(const Costmap& a, const Costmap& b, int min_i, int min_j, int max_i,
                         int max_j) {
  CellBounds w;
  const int sx = std::min(a.geometry().sizeX(), b.geometry().sizeX());
  const int sy = std::min(a.geometry().sizeY(), b.geometry().sizeY());
  min_i = std::max(min_i, 0), min_j = std::max(min_j, 0);
  max_i = std::min(max_i, sx), max_j = std::min(max_j, sy);
  if (min_i >= max_i || min_j >= max_j) return w;
  w.expand(min_i, min_j);
  w.expand(max_i - 1, max_j - 1);
  return w;
}

/// costmap_2d's updateWithMax rule for one cell.
inline std::uint8_t maxCombine(std::uint8_t layer, std::uint8_t master) {
  if (layer == cost::kNoInformation) return master;
  if (master == cost::kNoInformation || master < layer) return layer;
  return master;
}

}  // namespace

void copyStaticOverwrite(const Costmap& layer, Costmap* master, int min_i, int min_j, int max_i,
                         int max_j) {
  if (layer.geometry() != master->geometry()) return;
  const CellBounds w = clampedWindow(layer, *master, min_i, min_j, max_i, max_j);
  if (w.empty()) return;
  const std::size_t width = static_cast<std::size_t>(w.max_x - w.min_x + 1);
  for (int y = w.min_y; y <= w.max_y; ++y) {
    const std::size_t at = layer.geometry().index(w.min_x, y);
    std::memcpy(master->data() + at, layer.data() + at, width);
  }
}

void copyStaticMax(const Costmap& layer, Costmap* master, int min_i, int min_j, int max_i,
                   int max_j) {
  if (layer.geometry() != master->geometry()) return;
  const CellBounds w = clampedWindow(layer, *master, min_i, min_j, max_i, max_j);
  if (w.empty()) return;
  for (int y = w.min_y; y <= w.max_y; ++y) {
    const std::size_t at = layer.geometry().index(w.min_x, y);
    const std::uint8_t* in = layer.data() + at;
    std::uint8_t* out = master->data() + at;
    for (int x = 0; x <= w.max_x - w.min_x; ++x) out[x] = maxCombine(in[x], out[x]);
  }
}

std::size_t copyStaticSampled(const Costmap& layer, const Affine2D& layer_from_master,
                              bool use_maximum, Costmap* master, int min_i, int min_j, int max_i,
                              int max_j) {
  const GridGeometry& mg = master->geometry();
  const GridGeometry& lg = layer.geometry();
  min_i = std::max(min_i, 0), min_j = std::max(min_j, 0);
  max_i = std::min(max_i, mg.sizeX()), max_j = std::min(max_j, mg.sizeY());
  if (lg.cellCount() == 0) return 0;
  const Affine2D& t = layer_from_master;
  const double res = lg.resolution();
  std::size_t written = 0;
  for (int j = min_j; j < max_j; ++j) {
    double wy = 0.0, wx = 0.0;
    for (int i = min_i; i < max_i; ++i) {
      mg.cellCentre(i, j, &wx, &wy);
      const double lx = t.xx * wx + t.xy * wy + t.tx;
      const double ly = t.yx * wx + t.yy * wy + t.ty;
      // Divided, not multiplied by 1 / res: costmap_2d's worldToMap() rounds the same way.
      const double fx = std::floor((lx - lg.originX()) / res);
      const double fy = std::floor((ly - lg.originY()) / res);
      // Compared as doubles: a far-away (or NaN) point never reaches an int conversion.
      if (!(fx >= 0.0 && fy >= 0.0 && fx < lg.sizeX() && fy < lg.sizeY())) continue;
      const std::uint8_t c = layer.cost(static_cast<int>(fx), static_cast<int>(fy));
      master->setCost(i, j, use_maximum ? maxCombine(c, master->cost(i, j)) : c);
      ++written;
    }
  }
  return written;
}

}  // namespace downstream_perception
