#include "downstream_perception/core/log_odds_grid.h"

#include <algorithm>
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
  applyConfig(config);
  for (auto& raw : cells_) {
    const int v = std::clamp(unitsOfRaw(raw), clamp_min_units_, clamp_max_units_);
    raw = static_cast<std::int16_t>(v * 2);
  }
}

void LogOddsGrid::resize(const GridGeometry& geometry) {
  geometry_ = geometry;
  cells_.assign(geometry.cellCount(), 0);
}

void LogOddsGrid::reset() {
  std::fill(cells_.begin(), cells_.end(), 0);
}

void LogOddsGrid::setLogOdds(std::size_t i, double log_odds) {
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

void LogOddsGrid::shift(int dx, int dy) {
  if (dx == 0 && dy == 0) return;
  const int nx = geometry_.sizeX();
  const int ny = geometry_.sizeY();
  std::vector<std::int16_t> shifted(cells_.size(), 0);
  // Overlap of the old grid [dx, dx + nx) x [dy, dy + ny) with [0, nx) x [0, ny).
  const int x_lo = std::max(0, dx);
  const int x_hi = std::min(nx, nx + dx);
  const int y_lo = std::max(0, dy);
  const int y_hi = std::min(ny, ny + dy);
  if (x_lo < x_hi) {
    for (int y = y_lo; y < y_hi; ++y) {
      const auto src = cells_.begin() + static_cast<std::ptrdiff_t>(geometry_.index(x_lo, y));
      std::copy(src, src + (x_hi - x_lo),
                shifted.begin() + static_cast<std::ptrdiff_t>(geometry_.index(x_lo - dx, y - dy)));
    }
  }
  cells_.swap(shifted);
  geometry_ = GridGeometry(nx, ny, geometry_.resolution(),
                           geometry_.originX() + dx * geometry_.resolution(),
                           geometry_.originY() + dy * geometry_.resolution());
}

}  // namespace downstream_perception
