// A 2-D occupancy grid in fixed-point log-odds, 2 bytes per cell.
//
// Storage: each cell is one int16. Bits 1..15 hold the log-odds in units of kQuantum = 1/1024
// (range +-15.999); bit 0 is a scratch flag the scan integrator uses to update each cell at most
// once per scan (it is always clear between scans). Rounding: the hit/miss increments and the
// clamp limits are each rounded to the nearest quantum, so one update is off by at most
// kQuantum/2 = 0.00049 in log-odds (0.00012 in probability, since dp/dl <= 1/4); after n updates
// the stored value differs from the exact floating-point sum by at most n * kQuantum / 2. The
// error is deterministic (the same rounded increment every time), never random drift.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "downstream_perception/core/grid/grid_geometry.h"

namespace downstream_perception {

struct LogOddsConfig {
  double p_hit = 0.7;       ///< inverse sensor model: P(occupied) given a return in the cell
  double p_miss = 0.4;      ///< P(occupied) given a beam passing through the cell
  double clamp_min = -8.0;  ///< lower log-odds clamp (keeps free cells re-learnable)
  double clamp_max = 8.0;   ///< upper log-odds clamp (keeps walls un-learnable in bounded time)
  double occupied_threshold = 2.0;  ///< log-odds above this -> occupied (p > 0.881)
  double free_threshold = -2.0;     ///< log-odds below this -> free (p < 0.119)

  /// Empty if valid, else a message naming the offending field and value.
  std::string validate() const;
  bool operator==(const LogOddsConfig& o) const {
    return p_hit == o.p_hit && p_miss == o.p_miss && clamp_min == o.clamp_min &&
           clamp_max == o.clamp_max && occupied_threshold == o.occupied_threshold &&
           free_threshold == o.free_threshold;
  }
  bool operator!=(const LogOddsConfig& o) const { return !(*this == o); }
};

enum class CellState : std::int8_t { kUnknown = -1, kFree = 0, kOccupied = 1 };

class LogOddsGrid {
 public:
  static constexpr double kQuantum = 1.0 / 1024.0;
  static constexpr int kMaxUnits = 16383;  ///< largest |log-odds| in quanta (15.999)
  static constexpr double kMaxLogOdds = kMaxUnits * kQuantum;

  LogOddsGrid() = default;
  /// Throws std::invalid_argument if the config is invalid.
  explicit LogOddsGrid(const GridGeometry& geometry, const LogOddsConfig& config = {});

  const GridGeometry& geometry() const { return geometry_; }
  const LogOddsConfig& config() const { return config_; }
  /// Changes the sensor model and thresholds; the cells keep their evidence (re-clamped).
  void setConfig(const LogOddsConfig& config);
  /// Re-allocates to a new geometry; every cell becomes unknown (l = 0).
  void resize(const GridGeometry& geometry);
  /// All cells back to unknown (l = 0).
  void reset();

  static int quantize(double log_odds);
  static double dequantize(int units) { return units * kQuantum; }
  static double logOddsOf(double p);      ///< log(p / (1 - p))
  static double probabilityOf(double l);  ///< 1 - 1 / (1 + exp(l))

  int hitUnits() const { return hit_units_; }
  int missUnits() const { return miss_units_; }
  int clampMinUnits() const { return clamp_min_units_; }
  int clampMaxUnits() const { return clamp_max_units_; }

  // --- per-cell access (index = y * size_x + x) ---
  int units(std::size_t i) const { return unitsOfRaw(cells_[i]); }
  double logOdds(std::size_t i) const { return dequantize(units(i)); }
  double probability(std::size_t i) const { return probabilityOf(logOdds(i)); }
  CellState state(std::size_t i) const { return stateOfUnits(units(i)); }
  CellState stateOfUnits(int units) const {
    if (units > occupied_units_) return CellState::kOccupied;
    if (units < free_units_) return CellState::kFree;
    return CellState::kUnknown;
  }
  /// Sets a cell's log-odds (clamped and quantized). Clears its scratch flag.
  void setLogOdds(std::size_t i, double log_odds);
  /// Adds a signed number of quanta, clamped. Returns the new value in quanta.
  int addUnits(std::size_t i, int delta) {
    ++stamp_.version;
    const std::int16_t raw = cells_[i];
    int v = unitsOfRaw(raw) + delta;
    if (v > clamp_max_units_) v = clamp_max_units_;
    if (v < clamp_min_units_) v = clamp_min_units_;
    cells_[i] = static_cast<std::int16_t>(v * 2 + (raw & 1));
    return v;
  }
  int addHit(std::size_t i) { return addUnits(i, hit_units_); }
  int addMiss(std::size_t i) { return addUnits(i, miss_units_); }

  // --- scratch flag (used by the integrator to touch a cell once per scan) ---
  bool flagged(std::size_t i) const { return (cells_[i] & 1) != 0; }
  void setFlag(std::size_t i) {
    ++stamp_.version;
    cells_[i] = static_cast<std::int16_t>(cells_[i] | 1);
  }
  void clearFlag(std::size_t i) {
    ++stamp_.version;
    cells_[i] = static_cast<std::int16_t>(cells_[i] & ~1);
  }

  /// Raw storage (value * 2 + flag), for the integrator's inner loop only. Counts as a change of
  /// the cells (see stamp()): write through the pointer only before the next call of a method.
  std::int16_t* rawCells() {
    ++stamp_.version;
    return cells_.data();
  }
  const std::int16_t* rawCells() const { return cells_.data(); }
  int occupiedUnits() const { return occupied_units_; }
  int freeUnits() const { return free_units_; }

  /// Largest |log-odds| over the grid (health metric: should sit at the clamp, never beyond).
  double maxAbsLogOdds() const;
  /// Counts of (free, occupied, unknown) cells by the thresholds.
  void countStates(std::size_t* free_cells, std::size_t* occupied_cells,
                   std::size_t* unknown_cells) const;
  /// Bytes used by the cell storage (2 per cell).
  std::size_t memoryBytes() const { return cells_.size() * sizeof(std::int16_t); }

  /// Time decay toward unknown: every cell of `window` (inclusive, clamped) gets l <- l * factor,
  /// rounded toward zero, factor in [0, 1] (e.g. exp(-dt / tau)). Returns the window of the cells
  /// whose state (free/occupied/unknown) changed; counts them into *changed_cells if given.
  CellBounds decay(double factor, const CellBounds& window, std::size_t* changed_cells = nullptr);
  /// Shifts the content so that cell (dx, dy) of the old grid becomes cell (0, 0); cells that come
  /// into view are unknown, cells that leave are dropped. The origin moves by (dx, dy) cells.
  /// Any dx, dy; throws std::invalid_argument (and changes nothing) if the new origin would not
  /// be finite.
  void shift(int dx, int dy);

  /// Identifies the grid's cells as they are now: every non-const method (rawCells() included)
  /// moves `version`, and a copy or an assignment gets a new `id` (unique per process), so equal
  /// (id, version) means the same cells, unchanged since (the integrator's per-block memory of
  /// saturated blocks, see IntegrationScratch::block_free, relies on it).
  struct Stamp {
    std::uint64_t id = next();
    std::uint64_t version = 0;
    Stamp() = default;
    Stamp(const Stamp&) : id(next()) {}
    Stamp& operator=(const Stamp&) {
      id = next();
      version = 0;
      return *this;
    }
    static std::uint64_t next();
  };
  const Stamp& stamp() const { return stamp_; }

 private:
  static int unitsOfRaw(std::int16_t raw) { return (raw - (raw & 1)) / 2; }
  void applyConfig(const LogOddsConfig& config);

  GridGeometry geometry_;
  LogOddsConfig config_;
  std::vector<std::int16_t> cells_;
  Stamp stamp_;
  int hit_units_ = 0;
  int miss_units_ = 0;
  int clamp_min_units_ = 0;
  int clamp_max_units_ = 0;
  int occupied_units_ = 0;
  int free_units_ = 0;
};

}  // namespace downstream_perception
