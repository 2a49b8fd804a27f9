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

void runIntegration(int size, double room_half, int beams, int iters) {
  const GridGeometry geometry(size, size, 0.05, -size * 0.025, -size * 0.025);
  LogOddsGrid grid(geometry);
  ScanIntegratorConfig config;
  config.obstacle_max_range = 30.0;
  config.raytrace_max_range = 30.0;
  ScanIntegrator integrator(config);
  std::mt19937 rng(1);
  std::vector<std::vector<float>> scans;
  for (int i = 0; i < 16; ++i) scans.push_back(roomScan(beams, room_half, 0.01, rng));
  std::vector<double> ms;
  std::size_t cells = 0;
  for (int i = 0; i < iters + 5; ++i) {
    const auto& r = scans[i % scans.size()];
    LaserScanView view{r.data(), r.size(), -M_PI, 2.0 * M_PI / beams, 0.05, 30.0};
    const auto t0 = std::chrono::steady_clock::now();
    const IntegrationStats s = integrator.integrate(grid, view, {0.01, 0.02, 0.0});
    const auto t1 = std::chrono::steady_clock::now();
    if (i >= 5) {  // warm-up excluded
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      cells += s.cells_cleared + s.cells_marked;
    }
  }
  std::sort(ms.begin(), ms.end());
  const double median = ms[ms.size() / 2];
  const double p90 = ms[ms.size() * 9 / 10];
  const double cells_per_scan = static_cast<double>(cells) / iters;
  std::printf(
      "{\"bench\": \"scan_integration\", \"map\": %d, \"room_half_m\": %.3f, \"beams\": %d, "
      "\"iters\": %d, \"median_ms\": %.4f, \"p90_ms\": %.4f, \"cells_per_scan\": %.0f, "
      "\"mcells_per_s\": %.1f}\n",
      size, room_half, beams, iters, median, p90, cells_per_scan,
      cells_per_scan / (median * 1e-3) / 1e6);
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
  return 0;
}
