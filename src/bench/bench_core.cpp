// Core micro-benchmarks; prints one JSON object per line. scripts/bench.py runs this and writes
// the report table. Scenario (as in the costmap_2d anchor harness): robot at the centre of a
// square room (walls at +-room_half m) with two round pillars, 0.05 m cells, beams over 360 deg,
// range_max 30 m, obstacle and raytrace range 30 m, a freshly noised scan every iteration.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include "downstream_perception/core/inflation.h"
#include "downstream_perception/core/log_odds_costs.h"
#include "downstream_perception/core/scan_integrator.h"

using namespace downstream_perception;  // NOLINT

namespace {

double rayToCircle(double ox, double oy, double dx, double dy, double cx, double cy, double r) {
  const double fx = ox - cx;
  const double fy = oy - cy;
  const double b = fx * dx + fy * dy;
  const double c = fx * fx + fy * fy - r * r;
  const double disc = b * b - c;
  if (disc < 0.0) return INFINITY;
  const double t = -b - std::sqrt(disc);
  return t > 0.0 ? t : INFINITY;
}

std::vector<float> roomScan(int beams, double room_half, double noise, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, noise);
  std::vector<float> ranges(beams);
  const double s = room_half / 4.475;  // obstacles scale with the room
  for (int k = 0; k < beams; ++k) {
    const double a = -M_PI + k * 2.0 * M_PI / beams;
    const double dx = std::cos(a);
    const double dy = std::sin(a);
    double r = INFINITY;
    if (dx != 0) r = std::min(r, room_half / std::abs(dx));
    if (dy != 0) r = std::min(r, room_half / std::abs(dy));
    r = std::min(r, rayToCircle(0, 0, dx, dy, -2.0 * s, 2.0 * s, 0.25 * s));
    r = std::min(r, rayToCircle(0, 0, dx, dy, 1.0 * s, -2.5 * s, 0.4 * s));
    r += n(rng);
    ranges[k] = r > 30.0 ? INFINITY : static_cast<float>(r);
  }
  return ranges;
}

double medianOf(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double p90Of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() * 9 / 10];
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// One obstacle-layer update as the costmap runs it: integrate the scan, then write the states of
// the cells whose state changed into the master (what the layer reports as its bounds). Also
// timed: the write over the whole window the scan touched (costmap_2d merges that window every
// update) and the first scan into an empty (all-unknown) grid.
void runIntegration(int size, double room_half, int beams, int iters) {
  const GridGeometry geometry(size, size, 0.05, -size * 0.025, -size * 0.025);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 30.0;
  config.raytrace_max_range = 30.0;
  ScanIntegrator integrator(config);
  std::mt19937 rng(1);
  std::vector<std::vector<float>> scans;
  for (int i = 0; i < 16; ++i) scans.push_back(roomScan(beams, room_half, 0.01, rng));
  const Pose2D pose{0.01, 0.02, 0.0};
  const auto view = [&](int i) {
    const auto& r = scans[i % scans.size()];
    return LaserScanView{r.data(), r.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0};
  };

  std::vector<double> first;
  for (int i = 0; i < 5; ++i) {
    LogOddsGrid fresh(geometry);
    const auto t0 = std::chrono::steady_clock::now();
    integrator.integrate(fresh, view(i), pose);
    first.push_back(msSince(t0));
  }

  LogOddsGrid grid(geometry);
  Costmap master(geometry, cost::kNoInformation);
  std::vector<double> integrate_ms, layer_ms, touched_write_ms;
  std::size_t cells = 0;
  std::size_t changed = 0;
  for (int i = 0; i < iters + 20; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const IntegrationStats s = integrator.integrate(grid, view(i), pose);
    const double t_integrate = msSince(t0);
    writeStateCosts(grid, s.changed, false, cost::kNoInformation, &master);
    const double t_layer = msSince(t0);
    const auto t1 = std::chrono::steady_clock::now();
    writeStateCosts(grid, s.touched, false, cost::kNoInformation, &master);
    const double t_touched = msSince(t1);
    if (i >= 20) {  // warm-up (the grid converging to steady state) excluded
      integrate_ms.push_back(t_integrate);
      layer_ms.push_back(t_layer);
      touched_write_ms.push_back(t_touched);
      cells += s.cells_cleared + s.cells_marked;
      changed += s.cells_changed;
    }
  }
  const double median = medianOf(integrate_ms);
  const double cells_per_scan = static_cast<double>(cells) / iters;
  std::printf(
      "{\"bench\": \"scan_integration\", \"map\": %d, \"room_half_m\": %.3f, \"beams\": %d, "
      "\"iters\": %d, \"median_ms\": %.4f, \"p90_ms\": %.4f, \"layer_update_ms\": %.4f, "
      "\"touched_window_write_ms\": %.4f, \"first_scan_ms\": %.4f, \"cells_per_scan\": %.0f, "
      "\"cells_changed_per_scan\": %.1f, \"mcells_per_s\": %.1f}\n",
      size, room_half, beams, iters, median, p90Of(integrate_ms), medianOf(layer_ms),
      medianOf(touched_write_ms), medianOf(first), cells_per_scan,
      static_cast<double>(changed) / iters, cells_per_scan / (median * 1e-3) / 1e6);
}

// One whole costmap update as our costmap runs it on the anchor scenario (static map,
// track_unknown_space false, footprint inscribed radius 0.25 m): integrate the scan, reset the
// master window (cells whose obstacle state changed, grown by the inflation radius), write the
// obstacle states, inflate. Reports the inflation step and the whole update.
void runInflation(int size, double room_half, int beams, double radius, double csf, int iters) {
  const GridGeometry geometry(size, size, 0.05, -size * 0.025, -size * 0.025);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 30.0;
  config.raytrace_max_range = 30.0;
  ScanIntegrator integrator(config);
  InflationConfig ic;
  ic.inflation_radius = radius;
  ic.cost_scaling_factor = csf;
  ic.inscribed_radius = 0.25;
  Inflator inflator(ic, geometry.resolution());
  std::mt19937 rng(1);
  std::vector<std::vector<float>> scans;
  for (int i = 0; i < 16; ++i) scans.push_back(roomScan(beams, room_half, 0.01, rng));
  const Pose2D pose{0.01, 0.02, 0.0};
  LogOddsGrid grid(geometry);
  Costmap master(geometry, cost::kFreeSpace);
  CellBounds all;
  all.expand(0, 0);
  all.expand(size - 1, size - 1);
  // Converge the log-odds grid first (a robot that has been looking at the room for 2 s).
  for (int i = 0; i < 20; ++i) {
    const auto& r = scans[i % scans.size()];
    integrator.integrate(grid, {r.data(), r.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0}, pose);
  }
  writeStateCosts(grid, all, true, cost::kFreeSpace, &master);
  auto t_first = std::chrono::steady_clock::now();
  inflator.update(&master, all);
  const double first_ms = msSince(t_first);

  std::vector<double> inflate_ms, total_ms;
  std::size_t lethal_changed = 0, recomputed = 0;
  for (int i = 0; i < iters; ++i) {
    const auto& r = scans[i % scans.size()];
    const auto t0 = std::chrono::steady_clock::now();
    const IntegrationStats s = integrator.integrate(
        grid, {r.data(), r.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0}, pose);
    CellBounds window = s.changed;
    if (!window.empty()) {
      window.min_x -= inflator.radiusCells();
      window.min_y -= inflator.radiusCells();
      window.max_x += inflator.radiusCells();
      window.max_y += inflator.radiusCells();
      master.resetWindow(window);
      writeStateCosts(grid, window, true, cost::kFreeSpace, &master);
    }
    const auto t1 = std::chrono::steady_clock::now();
    const InflationStats st = inflator.update(&master, window);
    inflate_ms.push_back(msSince(t1));
    total_ms.push_back(msSince(t0));
    lethal_changed += st.lethal_changed;
    recomputed += st.cells_recomputed;
  }
  std::size_t lethal = 0, inscribed = 0, nonzero = 0;
  for (const std::uint8_t c : master.cells()) {
    lethal += c == cost::kLethalObstacle;
    inscribed += c == cost::kInscribedInflatedObstacle;
    nonzero += c != cost::kFreeSpace;
  }
  std::printf(
      "{\"bench\": \"inflation\", \"map\": %d, \"room_half_m\": %.3f, \"beams\": %d, "
      "\"radius_m\": %.2f, \"cost_scaling_factor\": %.1f, \"iters\": %d, "
      "\"inflation_median_ms\": %.4f, \"inflation_p90_ms\": %.4f, \"update_median_ms\": %.4f, "
      "\"first_full_inflation_ms\": %.4f, \"lethal_changed_per_update\": %.1f, "
      "\"cells_recomputed_per_update\": %.0f, \"lethal\": %zu, \"inscribed\": %zu, "
      "\"nonzero\": %zu}\n",
      size, room_half, beams, radius, csf, iters, medianOf(inflate_ms), p90Of(inflate_ms),
      medianOf(total_ms), first_ms, static_cast<double>(lethal_changed) / iters,
      static_cast<double>(recomputed) / iters, lethal, inscribed, nonzero);
}

}  // namespace

int main(int argc, char** argv) {
  int iters = 200;
  if (argc > 1) iters = std::max(10, std::atoi(argv[1]));
  const int only_size = argc > 2 ? std::atoi(argv[2]) : 0;  // 0 = all map sizes
  for (int size : {200, 1000}) {
    if (only_size != 0 && size != only_size) continue;
    const double room_half = size == 200 ? 4.475 : 22.475;
    for (int beams : {360, 1080, 3600}) runIntegration(size, room_half, beams, iters);
  }
  // The costmap_2d anchor scenarios (radius m, cost_scaling_factor).
  for (int size : {200, 1000}) {
    if (only_size != 0 && size != only_size) continue;
    const double room_half = size == 200 ? 4.475 : 22.475;
    for (double radius : {0.55, 1.0}) runInflation(size, room_half, 360, radius, 10.0, iters);
    if (size == 1000) runInflation(size, room_half, 3600, 2.5, 3.0, iters);
  }
  return 0;
}
