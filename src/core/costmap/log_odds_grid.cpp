#include "downstream_perception/core/costmap/log_odds_grid.h"

#include "downstream_perception/core/grid/grid_shift.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace downstream_perception {

std::string LogOddsConfig::validate() const {
  std::ostringstream why;
  const auto bad_probability = [](double p) { return !std::isfinite(p) || p <= 0.0 || p >= 1.0; };
  if (bad_probability(p_hit) || p_hit <= 0.5) {
    why << "p_hit must be in (0.5, 1), got " << p_hit;
  } else if (bad_probability(p_miss) || p_miss >= 0.5) {
    why << "p_miss must be in (0, 0.5), got " << p_miss;
  } else if (!std::isfinite(clamp_min) || !std::isfinite(clamp_max) || clamp_min >= 0.0 ||
             clamp_max <= 0.0 || clamp_max > LogOddsGrid::kMaxLogOdds ||
             clamp_min < -LogOddsGrid::kMaxLogOdds) {
    why << "clamp must satisfy -" << LogOddsGrid::kMaxLogOdds
        << " <= clamp_min < 0 < clamp_max <= " << LogOddsGrid::kMaxLogOdds << ", got [" << clamp_min
        << ", " << clamp_max << "]";
  } else if (!std::isfinite(occupied_threshold) || !std::isfinite(free_threshold) ||
             free_threshold > occupied_threshold) {
    why << "free_threshold (" << free_threshold << ") must not exceed occupied_threshold ("
        << occupied_threshold << ")";
  } else if (occupied_threshold >= clamp_max || free_threshold <= clamp_min) {
    why << "thresholds [" << free_threshold << ", " << occupied_threshold
        << "] must lie strictly inside the clamp [" << clamp_min << ", " << clamp_max
        << "], or no cell could ever be occupied/free";
  }
  return why.str();
}

std::uint64_t LogOddsGrid::Stamp::next() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
}

int LogOddsGrid::quantize(double log_odds) {
  const double units = std::round(log_odds / kQuantum);
  return static_cast<int>(
      std::clamp(units, -static_cast<double>(kMaxUnits), static_cast<double>(kMaxUnits)));
}

double LogOddsGrid::logOddsOf(double p) {
  return std::log(p / (1.0 - p));
}

double LogOddsGrid::probabilityOf(double l) {
  return 1.0 - 1.0 / (1.0 + std::exp(l));
}

LogOddsGrid::LogOddsGrid(const GridGeometry& geometry, const LogOddsConfig& config) {
  applyConfig(config);
  resize(geometry);
}

void LogOddsGrid::applyConfig(const LogOddsConfig& config) {
  ++stamp_.version;
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument(why);
  config_ = config;
  hit_units_ = quantize(logOddsOf(config.p_hit));
  miss_units_ = quantize(logOddsOf(config.p_miss));
  clamp_min_units_ = quantize(config.clamp_min);
  clamp_max_units_ = quantize(config.clamp_max);
  occupied_units_ = quantize(config.occupied_threshold);
  free_units_ = quantize(config.free_threshold);
}

void LogOddsGrid::setConfig(const LogOddsConfig& config) {
  ++stamp_.version;
  applyConfig(config);
  for (auto& raw : cells_) {
    const int v = std::clamp(unitsOfRaw(raw), clamp_min_units_, clamp_max_units_);
    raw = static_cast<std::int16_t>(v * 2);
  }
}

void LogOddsGrid::resize(const GridGeometry& geometry) {
  ++stamp_.version;
  geometry_ = geometry;
  cells_.assign(geometry.cellCount(), 0);
}

void LogOddsGrid::reset() {
  ++stamp_.version;
  std::fill(cells_.begin(), cells_.end(), 0);
}

void LogOddsGrid::setLogOdds(std::size_t i, double log_odds) {
  ++stamp_.version;
  const int v = std::clamp(quantize(log_odds), clamp_min_units_, clamp_max_units_);
  cells_[i] = static_cast<std::int16_t>(v * 2);
}

double LogOddsGrid::maxAbsLogOdds() const {
  int best = 0;
  for (const std::int16_t raw : cells_) best = std::max(best, std::abs(unitsOfRaw(raw)));
  return dequantize(best);
}

void LogOddsGrid::countStates(std::size_t* free_cells, std::size_t* occupied_cells,
                              std::size_t* unknown_cells) const {
  std::size_t n_free = 0;
  std::size_t n_occ = 0;
  for (const std::int16_t raw : cells_) {
    const int v = unitsOfRaw(raw);
    n_occ += v > occupied_units_ ? 1 : 0;
    n_free += v < free_units_ ? 1 : 0;
  }
  *free_cells = n_free;
  *occupied_cells = n_occ;
  *unknown_cells = cells_.size() - n_free - n_occ;
}

CellBounds LogOddsGrid::decay(double factor, const CellBounds& window, std::size_t* changed_cells) {
  ++stamp_.version;
  CellBounds changed;
  if (!(factor >= 0.0 && factor <= 1.0)) {
    throw std::invalid_argument("LogOddsGrid::decay: factor must be in [0, 1], got " +
                                std::to_string(factor));
  }
  CellBounds w;
  w.min_x = std::max(window.min_x, 0);
  w.min_y = std::max(window.min_y, 0);
  w.max_x = std::min(window.max_x, geometry_.sizeX() - 1);
  w.max_y = std::min(window.max_y, geometry_.sizeY() - 1);
  if (w.empty() || factor == 1.0) return changed;
  // Fixed-point factor (16 fractional bits); C++ division truncates toward zero, so a cell never
  // crosses zero and always reaches exactly 0 (unknown).
  const std::int64_t f = std::llround(factor * 65536.0);
  std::size_t count = 0;
  for (int y = w.min_y; y <= w.max_y; ++y) {
    std::int16_t* row = cells_.data() + geometry_.index(0, y);
    for (int x = w.min_x; x <= w.max_x; ++x) {
      const int before = unitsOfRaw(row[x]);
      if (before == 0) continue;
      const int after = static_cast<int>(before * f / 65536);
      row[x] = static_cast<std::int16_t>(after * 2 + (row[x] & 1));
      if (stateOfUnits(before) != stateOfUnits(after)) {
        changed.expand(x, y);
        ++count;
      }
    }
  }
  if (changed_cells != nullptr) *changed_cells += count;
  return changed;
}

void LogOddsGrid::shift(int dx, int dy) {
  ++stamp_.version;
  // The new geometry first: if its origin is not finite it throws and nothing has moved.
  const GridGeometry shifted = shiftedGeometry(geometry_, dx, dy);
  shiftGridData(&cells_, geometry_.sizeX(), geometry_.sizeY(), dx, dy, std::int16_t{0});
  geometry_ = shifted;
}

}  // namespace downstream_perception
