// The static map (map_server's nav_msgs/OccupancyGrid) as costs, with costmap_2d's StaticLayer
// semantics, ROS-free so that it is unit-tested and bound to Python.
//
// Value mapping (costmap_2d compares unsigned chars: the OccupancyGrid's int8 -1 is 255, and
// unknown_cost_value is converted the same way, so its default -1 matches -1 cells):
//   value == unknown_cost_value   -> NO_INFORMATION (255) if track_unknown_space, else FREE (0)
//   value >= lethal_cost_threshold -> LETHAL (254)   (so 101..254, i.e. int8 101..127 and
//                                                     -128..-2, are lethal)
//   trinary_costmap               -> FREE (0)
//   otherwise                     -> value / lethal_cost_threshold * 254, truncated
// lethal_cost_threshold is clamped to [0, 100] first.
//
// A full map replaces the layer's grid (geometry and costs); an update (map_msgs/
// OccupancyGridUpdate) rewrites a window of it. Both are checked first with 64-bit arithmetic
// and refused with a reason, leaving the previous grid untouched.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "downstream_perception/core/grid/costmap.h"
#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

struct StaticMapConfig {
  bool track_unknown_space = true;  ///< costmap_2d's StaticLayer default (layer level)
  bool use_maximum = false;         ///< combine with the master by max instead of overwriting
  int lethal_cost_threshold = 100;  ///< occupancy value (0..100) from which a cell is lethal
  int unknown_cost_value = -1;      ///< occupancy value meaning unknown (compared as a byte)
  bool trinary_costmap = true;      ///< false: below-lethal values scale to 0..253
  /// Largest map accepted (cells); a bigger one is refused. Bounds the layer's memory (one byte
  /// per cell here, one in the master, one in each published grid).
  std::size_t max_cells = std::size_t{1} << 26;
};

/// lethal_cost_threshold as costmap_2d uses it: clamped to [0, 100].
int clampedLethalThreshold(int lethal_cost_threshold);
/// costmap_2d's interpretValue() on one byte of an OccupancyGrid.
std::uint8_t interpretStaticValue(std::uint8_t value, const StaticMapConfig& config);
/// interpretStaticValue() for all 256 bytes (the layer maps cells by lookup).
std::array<std::uint8_t, 256> staticValueTable(const StaticMapConfig& config);

/// Structure of an incoming OccupancyGrid (only what the checks need).
struct StaticMapInfo {
  std::int64_t width = 0;                         ///< cells
  std::int64_t height = 0;                        ///< cells
  double resolution = 0.0;                        ///< m / cell
  double origin_x = 0.0;                          ///< m
  double origin_y = 0.0;                          ///< m
  double origin_z = 0.0;                          ///< m (ignored, must be finite)
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;  ///< orientation of the origin
  std::size_t data_size = 0;                      ///< number of values in data
};

/// Empty if the map can be used, else why not (sizes in 64 bits, data size == width * height,
/// resolution > 0 and finite, origin finite, orientation the identity, at most max_cells).
std::string validateStaticMap(const StaticMapInfo& info, std::size_t max_cells);

/// Planar affine map p' = [xx xy; yx yy] p + [tx; ty] (the map frame <- global frame transform
/// applied to points at z = 0, as costmap_2d applies it).
struct Affine2D {
  double xx = 1.0, xy = 0.0, yx = 0.0, yy = 1.0;
  double tx = 0.0, ty = 0.0;
  bool isIdentity() const {
    return xx == 1.0 && xy == 0.0 && yx == 0.0 && yy == 1.0 && tx == 0.0 && ty == 0.0;
  }
};

/// The inverse map (NaN coefficients if `a` is singular).
Affine2D invert(const Affine2D& a);
/// a(p).
inline void applyAffine(const Affine2D& a, double x, double y, double* ox, double* oy) {
  *ox = a.xx * x + a.xy * y + a.tx;
  *oy = a.yx * x + a.yy * y + a.ty;
}

/// Cell counts of a static grid (for diagnostics).
struct StaticCellCounts {
  std::size_t lethal = 0;
  std::size_t unknown = 0;
  std::size_t free = 0;
  std::size_t other = 0;  ///< scaled costs (trinary_costmap false)
};

class StaticMap {
 public:
  explicit StaticMap(const StaticMapConfig& config = StaticMapConfig());

  const StaticMapConfig& config() const { return config_; }
  bool hasMap() const { return has_map_; }
  /// The map as costs, in the map's own geometry.
  const Costmap& costs() const { return costs_; }
  /// The cells changed by the last successful setMap() / applyUpdate() (the whole map after a
  /// map, the update's window after an update).
  const CellBounds& lastChange() const { return last_change_; }
  const StaticCellCounts& counts() const { return counts_; }

  /// Replaces the map. Returns "" on success, else the reason (nothing changed).
  std::string setMap(const StaticMapInfo& info, const std::int8_t* data);
  /// Rewrites the window [x, x + width) x [y, y + height) from `data` (row-major, width * height
  /// values). Returns "" on success, else the reason (nothing changed): no map yet, a data size
  /// that is not width * height, or a window not inside the map.
  std::string applyUpdate(std::int64_t x, std::int64_t y, std::int64_t width, std::int64_t height,
                          const std::int8_t* data, std::size_t data_size);

 private:
  void countWindow(const CellBounds& window, int sign);

  StaticMapConfig config_;
  std::array<std::uint8_t, 256> table_;
  Costmap costs_;
  bool has_map_ = false;
  CellBounds last_change_;
  StaticCellCounts counts_;
};

/// costmap_2d's updateWithTrueOverwrite(): master = layer in [min_i, max_i) x [min_j, max_j).
/// Both grids must have the same geometry; the window is clamped to it.
void copyStaticOverwrite(const Costmap& layer, Costmap* master, int min_i, int min_j, int max_i,
                         int max_j);
/// costmap_2d's updateWithMax(): an unknown layer cell leaves the master alone; otherwise the
/// layer's cost wins where the master is unknown or lower.
void copyStaticMax(const Costmap& layer, Costmap* master, int min_i, int min_j, int max_i,
                   int max_j);
/// Different geometries (rolling window, another frame): each master cell in the window takes
/// the layer cell under its centre, mapped by `layer_from_master` (master's world frame to the
/// layer's world frame); master cells whose centre falls outside the layer are left alone.
/// use_maximum combines as copyStaticMax() does. Returns the number of master cells written to.
std::size_t copyStaticSampled(const Costmap& layer, const Affine2D& layer_from_master,
                              bool use_maximum, Costmap* master, int min_i, int min_j, int max_i,
                              int max_j);

}  // namespace downstream_perception
