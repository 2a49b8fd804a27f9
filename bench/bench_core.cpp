// Core micro-benchmarks; prints one JSON object per line. bench/bench.py runs this and writes
// the report table. Scenario (as in the costmap_2d anchor harness): robot at the centre of a
// square room (walls at +-room_half m) with two round pillars, 0.05 m cells, beams over 360 deg,
// range_max 30 m, obstacle and raytrace range 30 m, a freshly noised scan every iteration.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "downstream_perception/core/costmap/cloud_beams.h"
#include "downstream_perception/core/costmap/inflation.h"
#include "downstream_perception/core/costmap/log_odds_costs.h"
#include "downstream_perception/core/costmap/scan_integrator.h"
#include "downstream_perception/core/costmap/static_map.h"
#include "downstream_perception/core/tracking/tracker.h"
#include "downstream_perception/core/voxel/depth_rays.h"
#include "downstream_perception/core/voxel/voxel_map.h"

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

// FNV-1a over a grid's bytes: equal checksums in a row show bit-identical grids.
template <class T>
std::uint64_t checksumOf(const T* data, std::size_t n) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data);
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n * sizeof(T); ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

// One obstacle-layer update as the costmap runs it: integrate the scan, then write the states of
// the cells whose state changed into the master (what the layer reports as its bounds). Also
// timed: the write over the whole window the scan touched (costmap_2d merges that window every
// update) and the first scan into an empty (all-unknown) grid. Each update runs twice, in turn,
// on two grids fed the same scans: with the automatic clearing walk (what the layer runs: the
// walk it times as fastest, auto_walk_runs says which ran) and with the per-ray walk (the
// reference, as before issue 20), so both are timed in the same rounds; the grids' checksums show
// they stay bit-identical.
void runIntegration(int size, double room_half, int beams, int iters) {
  const GridGeometry geometry(size, size, 0.05, -size * 0.025, -size * 0.025);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 30.0;
  config.raytrace_max_range = 30.0;
  ScanIntegrator integrator(config);
  ScanIntegrator per_ray(config);
  per_ray.setClearingWalk(ClearingWalk::kPerRay);
  std::mt19937 rng(1);
  std::vector<std::vector<float>> scans;
  for (int i = 0; i < 16; ++i) scans.push_back(roomScan(beams, room_half, 0.01, rng));
  const Pose2D pose{0.01, 0.02, 0.0};
  const auto view = [&](int i) {
    const auto& r = scans[i % scans.size()];
    return LaserScanView{r.data(), r.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0};
  };

  std::vector<double> first, first_per_ray;
  for (int i = 0; i < 5; ++i) {
    for (ScanIntegrator* it : {&integrator, &per_ray}) {
      LogOddsGrid fresh(geometry);
      const auto t0 = std::chrono::steady_clock::now();
      it->integrate(fresh, view(i), pose);
      (it == &integrator ? first : first_per_ray).push_back(msSince(t0));
    }
  }

  struct Side {
    ScanIntegrator* integrator;
    LogOddsGrid grid;
    Costmap master;
    std::vector<double> integrate_ms, layer_ms;
  };
  Side sides[2] = {
      {&integrator, LogOddsGrid(geometry), Costmap(geometry, cost::kNoInformation), {}, {}},
      {&per_ray, LogOddsGrid(geometry), Costmap(geometry, cost::kNoInformation), {}, {}}};
  std::vector<double> touched_write_ms;
  Costmap touched_master(geometry, cost::kNoInformation);
  std::size_t cells = 0;
  std::size_t changed = 0;
  for (int i = 0; i < iters + 20; ++i) {
    for (int k = 0; k < 2; ++k) {
      Side& side = sides[(i + k) % 2];  // alternate which walk goes first
      const auto t0 = std::chrono::steady_clock::now();
      const IntegrationStats s = side.integrator->integrate(side.grid, view(i), pose);
      const double t_integrate = msSince(t0);
      writeStateCosts(side.grid, s.changed, false, cost::kNoInformation, &side.master);
      const double t_layer = msSince(t0);
      if (i < 20) continue;  // warm-up (the grid converging to steady state) excluded
      side.integrate_ms.push_back(t_integrate);
      side.layer_ms.push_back(t_layer);
      if (&side != &sides[0]) continue;
      const auto t1 = std::chrono::steady_clock::now();
      writeStateCosts(side.grid, s.touched, false, cost::kNoInformation, &touched_master);
      touched_write_ms.push_back(msSince(t1));
      cells += s.cells_cleared + s.cells_marked;
      changed += s.cells_changed;
    }
  }
  const double median = medianOf(sides[0].integrate_ms);
  const auto& runs = integrator.walkChooser().runs();
  const double cells_per_scan = static_cast<double>(cells) / iters;
  const std::size_t n = geometry.cellCount();
  const std::uint64_t sum = checksumOf(sides[0].grid.rawCells(), n);
  const std::uint64_t sum_per_ray = checksumOf(sides[1].grid.rawCells(), n);
  const std::uint64_t master_sum = checksumOf(sides[0].master.cells().data(), n);
  const std::uint64_t master_sum_per_ray = checksumOf(sides[1].master.cells().data(), n);
  std::printf(
      "{\"bench\": \"scan_integration\", \"map\": %d, \"room_half_m\": %.3f, \"beams\": %d, "
      "\"iters\": %d, \"median_ms\": %.4f, \"p90_ms\": %.4f, \"layer_update_ms\": %.4f, "
      "\"per_ray_median_ms\": %.4f, \"per_ray_layer_update_ms\": %.4f, "
      "\"touched_window_write_ms\": %.4f, \"first_scan_ms\": %.4f, "
      "\"per_ray_first_scan_ms\": %.4f, \"cells_per_scan\": %.0f, "
      "\"cells_changed_per_scan\": %.1f, \"mcells_per_s\": %.1f, \"grid_checksum\": \"%016llx\", "
      "\"per_ray_grid_checksum\": \"%016llx\", \"master_checksum\": \"%016llx\", "
      "\"per_ray_master_checksum\": \"%016llx\", \"auto_walk_runs\": {\"per_ray\": %llu, "
      "\"blocks\": %llu, \"reverse_query\": %llu, \"first_visit\": %llu, "
      "\"shared\": %llu}}\n",
      size, room_half, beams, iters, median, p90Of(sides[0].integrate_ms),
      medianOf(sides[0].layer_ms), medianOf(sides[1].integrate_ms), medianOf(sides[1].layer_ms),
      medianOf(touched_write_ms), medianOf(first), medianOf(first_per_ray), cells_per_scan,
      static_cast<double>(changed) / iters, cells_per_scan / (median * 1e-3) / 1e6,
      static_cast<unsigned long long>(sum), static_cast<unsigned long long>(sum_per_ray),
      static_cast<unsigned long long>(master_sum),
      static_cast<unsigned long long>(master_sum_per_ray),
      static_cast<unsigned long long>(runs[WalkChooser::kPerRay]),
      static_cast<unsigned long long>(runs[WalkChooser::kBlocks]),
      static_cast<unsigned long long>(runs[WalkChooser::kReverseQuery]),
      static_cast<unsigned long long>(runs[WalkChooser::kFirstVisit]),
      static_cast<unsigned long long>(runs[WalkChooser::kPerRayShared] +
                                      runs[WalkChooser::kBlocksShared] +
                                      runs[WalkChooser::kFirstVisitShared]));
}

// One whole costmap update as our costmap runs it on the anchor scenario (static map,
// track_unknown_space false, footprint inscribed radius 0.25 m): integrate the scan, reset the
// master window (cells whose obstacle state changed, grown by the inflation radius), write the
// obstacle states, inflate. Reports the inflation step and the whole update.
void runInflation(int size, double room_half, int beams, double radius, double csf, int iters,
                  const char* bench = "inflation") {
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
      "{\"bench\": \"%s\", \"map\": %d, \"room_half_m\": %.3f, \"beams\": %d, "
      "\"radius_m\": %.2f, \"cost_scaling_factor\": %.1f, \"iters\": %d, "
      "\"inflation_median_ms\": %.4f, \"inflation_p90_ms\": %.4f, \"update_median_ms\": %.4f, "
      "\"first_full_inflation_ms\": %.4f, \"lethal_changed_per_update\": %.1f, "
      "\"cells_recomputed_per_update\": %.0f, \"lethal\": %zu, \"inscribed\": %zu, "
      "\"nonzero\": %zu}\n",
      bench, size, room_half, beams, radius, csf, iters, medianOf(inflate_ms), p90Of(inflate_ms),
      medianOf(total_ms), first_ms, static_cast<double>(lethal_changed) / iters,
      static_cast<double>(recomputed) / iters, lethal, inscribed, nonzero);
}

// Rolling window: a 10 m x 10 m robot-centred map (200^2) while the robot drives 1 cell per
// update through a long corridor of pillars. Per update: shift master, obstacle grid and
// inflation cache by one cell, integrate a scan, redraw the whole window (as LayeredCostmap does
// after a shift), inflate. Compared with re-inflating the whole window from scratch.
void runRolling(int iters) {
  const int size = 200;
  ScanIntegratorConfig config;
  config.obstacle_max_range = 5.0;
  config.raytrace_max_range = 5.0;
  ScanIntegrator integrator(config);
  InflationConfig ic;
  ic.inflation_radius = 0.55;
  ic.inscribed_radius = 0.25;
  const int beams = 720;
  // Corridor walls at y = +-1.5 m with pillars every 2 m; ranges from the robot at (x, 0).
  const auto scan = [&](double x) {
    std::vector<float> r(beams);
    for (int k = 0; k < beams; ++k) {
      const double a = -M_PI + k * 2.0 * M_PI / beams;
      const double dx = std::cos(a), dy = std::sin(a);
      double range = dy != 0 ? 1.5 / std::abs(dy) : INFINITY;
      for (double px = std::floor(x / 2.0) * 2.0 - 6.0; px < x + 8.0; px += 2.0) {
        range = std::min(range, rayToCircle(x, 0.0, dx, dy, px, 0.9, 0.15));
      }
      r[k] = range > 30.0 ? INFINITY : static_cast<float>(range);
    }
    return r;
  };
  Inflator incremental(ic, 0.05);
  Inflator scratch(ic, 0.05);
  GridGeometry geometry(size, size, 0.05, -5.0, -5.0);
  LogOddsGrid grid(geometry);
  Costmap master(geometry, cost::kNoInformation);
  CellBounds all;
  all.expand(0, 0);
  all.expand(size - 1, size - 1);
  std::vector<double> update_ms, shift_inflate_ms, full_inflate_ms;
  for (int i = 0; i < iters + 10; ++i) {
    const double x = 0.05 * i;
    const auto ranges = scan(x);
    const auto t0 = std::chrono::steady_clock::now();
    if (i > 0) {
      master.shift(1, 0);
      grid.shift(1, 0);
      incremental.shift(1, 0);
    }
    integrator.integrate(
        grid, {ranges.data(), ranges.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0}, {x, 0.0, 0.0});
    master.reset();
    writeStateCosts(grid, all, false, cost::kFreeSpace, &master);
    Costmap copy = master;
    const auto t1 = std::chrono::steady_clock::now();
    incremental.update(&master, all);
    const double t_inflate = msSince(t1);
    const double t_update = msSince(t0);
    const auto t2 = std::chrono::steady_clock::now();
    scratch.reset();
    scratch.update(&copy, all);
    const double t_full = msSince(t2);
    if (i >= 10) {
      update_ms.push_back(t_update);
      shift_inflate_ms.push_back(t_inflate);
      full_inflate_ms.push_back(t_full);
    }
  }
  std::printf(
      "{\"bench\": \"rolling\", \"map\": %d, \"beams\": %d, \"radius_m\": 0.55, \"iters\": %d, "
      "\"update_median_ms\": %.4f, \"inflation_median_ms\": %.4f, "
      "\"full_reinflation_median_ms\": %.4f}\n",
      size, beams, iters, medianOf(update_ms), medianOf(shift_inflate_ms),
      medianOf(full_inflate_ms));
}

// A 640 x 480 depth camera (307,200 points) 0.4 m above the floor looking at a wall 4 m away:
// the lower part of the image sees the floor (outside the height band), the rest the wall.
void runCloud(int iters) {
  const int w = 640, h = 480;
  std::vector<float> xyz;
  xyz.reserve(static_cast<std::size_t>(w) * h * 3);
  const double fx = 525.0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      // Camera frame x forward, y left, z up (already rotated to the body convention).
      const double dy = -(u - w / 2.0) / fx;
      const double dz = -(v - h / 2.0) / fx;
      double t = 4.0;                            // wall at x = 4 m
      if (dz < 0.0) t = std::min(t, 0.4 / -dz);  // floor 0.4 m below the camera
      xyz.push_back(static_cast<float>(t));
      xyz.push_back(static_cast<float>(t * dy));
      xyz.push_back(static_cast<float>(t * dz));
    }
  }
  const GridGeometry geometry(200, 200, 0.05, -5.0, -5.0);
  LogOddsGrid grid(geometry);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 5.0;
  config.raytrace_max_range = 5.0;
  ScanIntegrator integrator(config);
  CloudBeamsConfig cloud;
  cloud.min_obstacle_height = 0.05;
  cloud.max_obstacle_height = 1.8;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation().z() = 0.4;
  // Median (beam making ms, integration ms, beams) of `iters` clouds with one config.
  const auto run = [&](const CloudBeamsConfig& c) {
    std::vector<double> beams_ms, integrate_ms;
    std::vector<BeamUpdate> beams;
    for (int i = 0; i < iters; ++i) {
      beams.clear();
      IntegrationStats decisions;
      const auto t0 = std::chrono::steady_clock::now();
      beamsFromCloud(integrator, c, reinterpret_cast<const unsigned char*>(xyz.data()),
                     static_cast<std::size_t>(w) * h, 3 * sizeof(float), pose, &beams, &decisions);
      beams_ms.push_back(msSince(t0));
      const auto t1 = std::chrono::steady_clock::now();
      integrator.integrate(grid, beams, decisions);
      integrate_ms.push_back(msSince(t1));
    }
    return std::make_tuple(medianOf(beams_ms), medianOf(integrate_ms), beams.size());
  };
  CloudBeamsConfig merged = cloud;
  merged.merge_grid = geometry;
  const auto [merged_beams_ms, merged_integrate_ms, merged_beams] = run(merged);
  const auto [beams_ms, integrate_ms, beams_in_band] = run(cloud);
  std::printf(
      "{\"bench\": \"cloud\", \"points\": %d, \"beams_in_band\": %zu, \"iters\": %d, "
      "\"beams_median_ms\": %.4f, \"integrate_median_ms\": %.4f, \"merged_beams\": %zu, "
      "\"merged_beams_median_ms\": %.4f, \"merged_integrate_median_ms\": %.4f}\n",
      w * h, beams_in_band, iters, beams_ms, integrate_ms, merged_beams, merged_beams_ms,
      merged_integrate_ms);
}

// One decay pass over a 1000^2 grid whose every cell holds evidence.
void runDecay(int iters) {
  const GridGeometry geometry(1000, 1000, 0.05, 0.0, 0.0);
  LogOddsGrid grid(geometry);
  CellBounds all;
  all.expand(0, 0);
  all.expand(999, 999);
  std::vector<double> ms;
  for (int i = 0; i < iters; ++i) {
    if (i % 20 == 0) {
      for (std::size_t c = 0; c < geometry.cellCount(); ++c) grid.setLogOdds(c, c % 2 ? 8.0 : -8.0);
    }
    const auto t0 = std::chrono::steady_clock::now();
    grid.decay(0.95, all);
    ms.push_back(msSince(t0));
  }
  std::printf("{\"bench\": \"decay\", \"map\": 1000, \"iters\": %d, \"median_ms\": %.4f}\n", iters,
              medianOf(ms));
}

// Tracker throughput: N objects moving at constant velocity (bouncing off the walls of a square
// sized for ~1 object per 25 m^2), 10 Hz, 90 % detection probability, 0.1 m noise, 5 % clutter.
void runTracker(int n, int frames) {
  std::mt19937 rng(11);
  const double half = std::sqrt(25.0 * n) / 2.0;
  std::uniform_real_distribution<double> pos(-half, half), vel(-1.5, 1.5), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<std::array<double, 4>> objects(n);
  std::vector<int> truth(n);
  int next_truth = 0;
  for (int i = 0; i < n; ++i) {
    objects[i] = {pos(rng), pos(rng), vel(rng), vel(rng)};
    truth[i] = next_truth++;
  }
  Tracker tracker;
  std::vector<double> us;
  std::size_t switches = 0;
  std::vector<Detection> detections;
  for (int f = 0; f < frames + 20; ++f) {
    detections.clear();
    for (int i = 0; i < n; ++i) {
      auto& o = objects[i];
      o[0] += 0.1 * o[2];
      o[1] += 0.1 * o[3];
      if (std::abs(o[0]) > half || std::abs(o[1]) > half) {
        // Left the area: a new object enters elsewhere (a new truth id, not a bounce).
        o = {pos(rng), pos(rng), vel(rng), vel(rng)};
        truth[i] = next_truth++;
      }
      if (unit(rng) < 0.9) {
        Detection d;
        d.x = o[0] + noise(rng);
        d.y = o[1] + noise(rng);
        d.score = 0.6 + 0.4 * unit(rng);
        d.truth_id = truth[i];
        detections.push_back(d);
      }
    }
    for (int c = 0; c < std::max(1, n / 20); ++c) {
      Detection d;
      d.x = pos(rng);
      d.y = pos(rng);
      d.score = 0.5 * unit(rng) + 0.3;
      detections.push_back(d);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const TrackerStats s = tracker.step(0.1 * f, detections);
    if (f >= 20) {
      us.push_back(msSince(t0) * 1000.0);
      switches += s.id_switches;
    }
  }
  std::printf(
      "{\"bench\": \"tracker\", \"objects\": %d, \"frames\": %d, \"median_us\": %.2f, "
      "\"p90_us\": %.2f, \"id_switches\": %zu}\n",
      n, frames, medianOf(us), p90Of(us), switches);
}

// Image-mode throughput (issue 21): N boxes of person shape (50-150 px tall) drifting across a
// 640 x 480 image at 25 fps (new ones enter where one leaves), 90 % detection probability, box
// edges noisy by 3 % of the height, N/10 false positives per frame; the IMAGE defaults.
void runImageTracker(int n, int frames) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> x(0.0, 600.0), y(0.0, 330.0), h(50.0, 150.0),
      vel(-60.0, 60.0), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  struct Person {
    double x, y, h, vx, vy;
  };
  const auto enter = [&] { return Person{x(rng), y(rng), h(rng), vel(rng), vel(rng)}; };
  std::vector<Person> people(n);
  for (auto& p : people) p = enter();
  Tracker tracker(TrackerConfig::defaultsFor(TrackerConfig::Mode::kImage));
  std::vector<double> us;
  std::vector<Detection> detections;
  const double dt = 1.0 / 25.0;
  for (int f = 0; f < frames + 20; ++f) {
    detections.clear();
    for (auto& p : people) {
      p.x += p.vx * dt;
      p.y += p.vy * dt;
      if (p.x < 0.0 || p.x > 620.0 || p.y < 0.0 || p.y > 470.0 - p.h) p = enter();
      if (unit(rng) >= 0.9) continue;
      const double s = 0.03 * p.h;
      Detection d;
      d.box = {p.x + s * noise(rng), p.y + s * noise(rng), p.x + 0.4 * p.h + s * noise(rng),
               p.y + p.h + s * noise(rng)};
      d.score = 0.6 + 0.4 * unit(rng);
      detections.push_back(d);
    }
    for (int c = 0; c < std::max(1, n / 10); ++c) {
      const Person p = enter();
      Detection d;
      d.box = {p.x, p.y, p.x + 0.4 * p.h, p.y + p.h};
      d.score = 0.5 * unit(rng) + 0.2;
      detections.push_back(d);
    }
    const auto t0 = std::chrono::steady_clock::now();
    tracker.step(dt * f, detections);
    if (f >= 20) us.push_back(msSince(t0) * 1000.0);
  }
  std::printf(
      "{\"bench\": \"tracker_image\", \"objects\": %d, \"frames\": %d, \"median_us\": %.2f, "
      "\"p90_us\": %.2f}\n",
      n, frames, medianOf(us), p90Of(us));
}

// The static layer: a map_server-sized map (4000 x 4000 cells, 200 m at 0.05 m: walls every 5 m,
// an unknown border) mapped to costs, a 100 x 100 OccupancyGridUpdate applied, and the copies into
// the master (whole map after a map, the window after an update).
void runStaticMap(int iters) {
  const int n = 4000, w = 100;
  std::vector<std::int8_t> data(static_cast<std::size_t>(n) * n, 0);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      std::int8_t& v = data[static_cast<std::size_t>(y) * n + x];
      if (x < 20 || y < 20 || x >= n - 20 || y >= n - 20) {
        v = -1;
      } else if (x % 100 == 0 || y % 100 == 0) {
        v = 100;
      }
    }
  }
  std::vector<std::int8_t> update(static_cast<std::size_t>(w) * w, 100);
  StaticMapInfo info;
  info.width = n, info.height = n, info.resolution = 0.05, info.origin_x = -100.0;
  info.origin_y = -100.0, info.data_size = data.size();
  StaticMap map;
  Costmap master(GridGeometry(n, n, 0.05, -100.0, -100.0), cost::kNoInformation);
  std::vector<double> set_ms, update_us, copy_all_ms, copy_window_us;
  const int map_reps = std::max(5, iters / 20);
  for (int k = 0; k < map_reps; ++k) {
    auto t0 = std::chrono::steady_clock::now();
    if (!map.setMap(info, data.data()).empty()) std::abort();
    set_ms.push_back(msSince(t0));
    t0 = std::chrono::steady_clock::now();
    copyStaticOverwrite(map.costs(), &master, 0, 0, n, n);
    copy_all_ms.push_back(msSince(t0));
  }
  for (int k = 0; k < iters; ++k) {
    const int x = (k * 137) % (n - w), y = (k * 311) % (n - w);
    auto t0 = std::chrono::steady_clock::now();
    if (!map.applyUpdate(x, y, w, w, update.data(), update.size()).empty()) std::abort();
    update_us.push_back(msSince(t0) * 1000.0);
    t0 = std::chrono::steady_clock::now();
    copyStaticOverwrite(map.costs(), &master, x, y, x + w, y + w);
    copy_window_us.push_back(msSince(t0) * 1000.0);
  }
  std::printf(
      "{\"bench\": \"static_map\", \"cells\": %d, \"update_cells\": %d, "
      "\"set_map_median_ms\": %.2f, \"copy_map_median_ms\": %.2f, "
      "\"update_median_us\": %.2f, \"update_p90_us\": %.2f, \"copy_update_median_us\": %.2f, "
      "\"lethal_cells\": %zu}\n",
      n * n, w * w, medianOf(set_ms), medianOf(copy_all_ms), medianOf(update_us), p90Of(update_us),
      medianOf(copy_window_us), map.counts().lethal);
}

// A 640x480 depth frame (fx = fy = 525 px) into the 3-D voxel map: 5 cm voxels (x, y and z, 40
// layers: 0 .. 2 m), a 10 m x 10 m rolling window, marking and clearing to 4 m, no-return rays
// (+Inf) clearing 4 m. Scene: camera at 1 m height pitched 15 deg down, floor, a wall 3.5 m ahead,
// a 0.5 m box 2 m ahead, a table top (0.75 m) 1.5 m ahead on the left; depths beyond 4.5 m are
// no-returns. A freshly noised frame (1 cm) every iteration. Timed: rays (back-projection) and
// integration separately, and the column projection of the whole window.
void runVoxel(int iters, int stride, bool clearing, bool one_ray_per_end_voxel = false,
              bool frustum = false) {
  PinholeCamera cam;
  cam.width = 640;
  cam.height = 480;
  cam.fx = cam.fy = 525.0;
  cam.cx = 319.5;
  cam.cy = 239.5;
  const double pitch = 15.0 * M_PI / 180.0;
  // Optical frame (z forward, x right, y down) -> world (x forward, y left, z up), pitched down.
  Eigen::Matrix3d optical_to_level;
  optical_to_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d pitch_down = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).matrix();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = pitch_down * optical_to_level;
  pose.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<float> depth(static_cast<std::size_t>(cam.width) * cam.height);
  const auto render = [&] {
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const Eigen::Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
        const Eigen::Vector3d d = pose.linear() * ray;  // per unit of optical depth
        const Eigen::Vector3d o = pose.translation();
        double t = INFINITY;
        if (d.z() < 0) t = std::min(t, -o.z() / d.z());                 // floor
        if (d.x() > 0) t = std::min(t, (3.5 - o.x()) / d.x());          // wall
        const auto box = [&](Eigen::Vector3d lo, Eigen::Vector3d hi) {  // slab test
          double t0 = 0.0, t1 = INFINITY;
          for (int a = 0; a < 3; ++a) {
            if (d(a) == 0.0) {
              if (o(a) < lo(a) || o(a) > hi(a)) return;
              continue;
            }
            double ta = (lo(a) - o(a)) / d(a), tb = (hi(a) - o(a)) / d(a);
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta);
            t1 = std::min(t1, tb);
          }
          if (t0 <= t1 && t0 > 0) t = std::min(t, t0);
        };
        box({1.75, -0.25, 0.0}, {2.25, 0.25, 0.5});
        box({1.2, 0.3, 0.72}, {2.0, 1.1, 0.77});
        const double r = t * d.norm();
        depth[static_cast<std::size_t>(v) * cam.width + u] =
            r > 4.5 ? INFINITY : static_cast<float>(t + noise(rng));
      }
    }
  };
  VoxelMapConfig config;
  config.resolution_m = 0.05;
  config.z_resolution_m = 0.05;
  config.z_voxels = 40;
  config.min_obstacle_height_m = 0.1;
  VoxelMap map(config, -5.0, -5.0, 200, 200);
  VoxelRayConfig rays;
  rays.obstacle_max_range_m = 4.0;
  rays.raytrace_max_range_m = 4.0;
  rays.no_return_range_m = 4.0;
  rays.clearing = clearing;
  rays.one_ray_per_end_voxel = one_ray_per_end_voxel;
  DepthRays out;
  std::vector<double> ray_ms, integrate_ms, project_ms;
  std::vector<std::uint8_t> costs;
  VoxelIntegrationStats last;
  for (int k = 0; k < iters; ++k) {
    render();
    auto t0 = std::chrono::steady_clock::now();
    if (frustum) {  // back-projection, marking and frustum clearing in one call
      ray_ms.push_back(0.0);
      last = map.integrateDepthFrustum(depth.data(), cam, pose, false, stride, 0.1 * k, rays);
    } else {
      depthToRays(depth.data(), cam, pose, false, stride, &out);
      ray_ms.push_back(msSince(t0));
      t0 = std::chrono::steady_clock::now();
      last = map.integrate(pose.translation(), out.hits.data(), out.hits.size() / 3,
                           out.no_returns.data(), out.no_returns.size() / 3, 0.1 * k, rays);
    }
    integrate_ms.push_back(msSince(t0));
    t0 = std::chrono::steady_clock::now();
    map.project(0.1 * k, &costs);
    project_ms.push_back(msSince(t0));
  }
  std::vector<double> total(iters);
  for (int k = 0; k < iters; ++k) total[k] = ray_ms[k] + integrate_ms[k];
  const auto lethal = static_cast<std::size_t>(
      std::count(costs.begin(), costs.end(), static_cast<std::uint8_t>(254)));
  std::printf(
      "{\"bench\": \"voxel_depth\", \"width\": 640, \"height\": 480, \"stride\": %d, "
      "\"clearing\": %s, \"clearing_mode\": \"%s\", \"one_ray_per_end_voxel\": %s, "
      "\"voxel_m\": 0.05, \"range_m\": 4.0, "
      "\"iters\": %d, \"rays\": %zu, "
      "\"voxels_walked\": %zu, \"marked\": %zu, \"cleared\": %zu, \"frame_median_ms\": %.3f, "
      "\"frame_p90_ms\": %.3f, \"rays_median_ms\": %.3f, \"integrate_median_ms\": %.3f, "
      "\"project_median_ms\": %.3f, \"blocks\": %zu, \"memory_bytes\": %zu, \"lethal_columns\": "
      "%zu}\n",
      stride, clearing ? "true" : "false", frustum ? "frustum" : "ray",
      one_ray_per_end_voxel ? "true" : "false", iters, last.rays, last.voxels_walked, last.marked,
      last.cleared, medianOf(total), p90Of(total), medianOf(ray_ms), medianOf(integrate_ms),
      medianOf(project_ms), map.blocks(), map.memoryBytes(), lethal);
}

void runVoxelRows(int iters) {
  const int n = std::max(10, iters / 10);
  runVoxel(n, 1, true);        // every pixel, marking and clearing: the goal (<= 3 ms)
  runVoxel(n, 1, false);       // marking only: what the clearing costs
  runVoxel(n, 2, true);        // every 2nd pixel in x and y
  runVoxel(n, 1, true, true);  // every pixel, one ray per end voxel
  runVoxel(n, 1, true, false, true);  // frustum clearing, every pixel marks
  runVoxel(n, 2, true, false, true);  // frustum clearing, every 2nd pixel marks (all clear)
}

}  // namespace

int main(int argc, char** argv) {
  int iters = 200;
  if (argc > 1) iters = std::max(10, std::atoi(argv[1]));
  if (argc > 2 && std::strcmp(argv[2], "static") == 0) {  // the static-map rows only
    runStaticMap(iters);
    return 0;
  }
  if (argc > 2 && std::strcmp(argv[2], "voxel") == 0) {  // the voxel-map rows only
    runVoxelRows(iters);
    return 0;
  }
  const int only_size = argc > 2 ? std::atoi(argv[2]) : 0;  // 0 = all map sizes
  // Scan integration against beams and map size (bench_scan.png): costmap_2d's anchor rooms
  // (walls at +-4.475 m on 200^2, +-22.475 m on 1000^2) and one between them.
  const std::pair<int, double> scan_rooms[] = {{200, 4.475}, {500, 11.975}, {1000, 22.475}};
  for (const auto& [size, room_half] : scan_rooms) {
    if (only_size != 0 && size != only_size) continue;
    for (int beams : {360, 1080, 3600}) runIntegration(size, room_half, beams, iters);
  }
  // The costmap_2d anchor scenarios (radius m, cost_scaling_factor).
  for (int size : {200, 1000}) {
    if (only_size != 0 && size != only_size) continue;
    const double room_half = size == 200 ? 4.475 : 22.475;
    for (double radius : {0.55, 1.0}) runInflation(size, room_half, 360, radius, 10.0, iters);
    if (size == 1000) runInflation(size, room_half, 3600, 2.5, 3.0, iters);
  }
  if (only_size != 0) return 0;
  // Update time against inflation radius and map size (the plot in bench.md).
  for (int size : {200, 500, 1000}) {
    const double room_half = size * 0.025 - 0.525;
    for (double radius : {0.25, 0.55, 1.0, 1.5, 2.5}) {
      runInflation(size, room_half, 360, radius, 3.0, iters, "inflation_sweep");
    }
  }
  runRolling(iters);
  runCloud(std::max(10, iters / 10));
  runDecay(std::max(10, iters / 4));
  for (int n : {10, 50, 200}) runTracker(n, std::max(100, iters * 2));
  for (int n : {10, 50}) runImageTracker(n, std::max(100, iters * 2));
  runStaticMap(iters);
  runVoxelRows(iters);
  return 0;
}
