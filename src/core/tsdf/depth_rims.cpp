#include "downstream_perception/core/tsdf/depth_rims.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "downstream_perception/core/parallel/avx2_clones.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace downstream_perception {

// Both passes read memory contiguously: the vertical nearest seed by sweeping whole rows (down,
// then up), the exact transform by the lower envelope of parabolas along each row.
DP_AVX2_CLONES
void seedDistances(int w, int h, const std::uint8_t* seeds, SeedDistances* out,
                   float max_distance_px, std::initializer_list<const float*> planes) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const float none = SeedDistances::kNoSeed;
  out->squared.resize(n);
  out->seed.resize(n);
  out->seed_values.resize(planes.size());
  for (auto& values : out->seed_values) values.resize(n);
  out->column_seed_row.resize(n);
  out->column_squared.resize(static_cast<std::size_t>(w));
  out->hull.resize(static_cast<std::size_t>(w));
  out->hull_f.resize(static_cast<std::size_t>(w));
  // The nearest seed in the same column: above (sweeping down), then the nearer of that and the
  // one below (sweeping up, the nearest below carried in a row-long scratch). -1: none.
  std::int32_t* row_of = out->column_seed_row.data();
  for (int u = 0; u < w; ++u) row_of[u] = seeds[u] ? 0 : -1;
  for (int v = 1; v < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) row_of[row + u] = seeds[row + u] ? v : row_of[row - w + u];
  }
  std::int32_t* below = out->column_squared.data();  // scratch until the row pass
  std::fill(below, below + w, -1);
  for (int v = h - 1; v >= 0; --v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      const std::int32_t down = seeds[row + u] ? v : below[u];
      below[u] = down;
      const std::int32_t up = row_of[row + u];
      const bool take_down = (down >= 0) & ((up < 0) | (down - v < v - up));
      row_of[row + u] = take_down ? down : up;
    }
  }
  // Along each row: the lower envelope of the parabolas (u - q)^2 + g(q), g the squared
  // distance to q's nearest seed in its column, with its intersections compared by
  // cross-multiplying in 64-bit integers (exact, and no division in the loop's dependency chain).
  std::int32_t* g = out->column_squared.data();
  std::int32_t* hull = out->hull.data();
  std::int64_t* hull_f = out->hull_f.data();
  // Parabolas whose apex lies max_distance_px or more above the row cannot bring a pixel nearer
  // than that: left out (most of them, far from the rims).
  const double max_squared = static_cast<double>(max_distance_px) * max_distance_px;
  const std::int32_t limit = max_squared < 2147483647.0
                                 ? static_cast<std::int32_t>(std::ceil(max_squared))
                                 : std::numeric_limits<std::int32_t>::max();
  // The run fill's squared distances in 32-bit integers where they fit (its int-to-float
  // conversion vectorises, the 64-bit one does not; both round the same value the same way):
  // every g kept is below the limit and every |u - q| below w.
  const bool fits_32 =
      static_cast<std::int64_t>(w) * w + limit <= std::numeric_limits<std::int32_t>::max();
  for (int v = 0; v < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const std::int32_t* seed_row = row_of + row;
    for (int u = 0; u < w; ++u) {
      const std::int32_t dv = v - seed_row[u];
      const std::int32_t squared = dv * dv;  // < 2^31: h <= 16384 px
      g[u] = (seed_row[u] < 0) | (squared >= limit) ? -1 : squared;
    }
    int top = -1;
    for (int q = 0; q < w; ++q) {
      if (g[q] < 0) continue;
      const std::int64_t fq = g[q] + static_cast<std::int64_t>(q) * q;
      // Pop the top parabola while q's overtakes it no later than it overtook the one below:
      // (fq - fp) / 2(q - p) <= (fp - fpp) / 2(p - pp).
      while (top >= 1) {
        const std::int64_t p = hull[top], pp = hull[top - 1];
        const std::int64_t fp = hull_f[top], fpp = hull_f[top - 1];
        if ((fq - fp) * (p - pp) > (fp - fpp) * (q - p)) break;
        --top;
      }
      ++top;
      hull[top] = q;
      hull_f[top] = fq;
    }
    float* squared_out = out->squared.data() + row;
    std::int32_t* seed_out = out->seed.data() + row;
    if (top < 0) {
      std::fill(squared_out, squared_out + w, none);
      std::fill(seed_out, seed_out + w, -1);
      for (auto& values : out->seed_values)
        std::fill(values.data() + row, values.data() + row + w, none);
      continue;
    }
    // Each envelope parabola's run of pixels, filled in one go (no per-pixel branch): parabola
    // k + 1 is at least as low from the first u with (f1 - f0) <= 2 u (h1 - h0); the quotient in
    // double, then made exact by the integer test.
    int u = 0;
    for (int k = 0; k <= top; ++k) {
      int end = w;
      if (k < top) {
        const std::int64_t df = hull_f[k + 1] - hull_f[k];
        const std::int64_t dh = 2 * static_cast<std::int64_t>(hull[k + 1] - hull[k]);
        auto first =
            static_cast<std::int64_t>(std::ceil(static_cast<double>(df) / static_cast<double>(dh)));
        while (df <= (first - 1) * dh) --first;
        while (df > first * dh) ++first;
        end = static_cast<int>(std::min<std::int64_t>(std::max<std::int64_t>(first, u), w));
      }
      const int q = hull[k];
      const std::int32_t nearest = seed_row[q] * w + q;
      const auto fill = [&](auto gq) {  // gq's type: the arithmetic's width
        for (int x = u; x < end; ++x) {
          const decltype(gq) du = x - q;
          squared_out[x] = static_cast<float>(du * du + gq);
          seed_out[x] = nearest;
        }
      };
      if (fits_32) {
        fill(static_cast<std::int32_t>(g[q]));
      } else {
        fill(static_cast<std::int64_t>(g[q]));
      }
      std::size_t plane = 0;
      for (const float* values : planes) {
        float* value_out = out->seed_values[plane++].data() + row;
        std::fill(value_out + u, value_out + end, values[nearest]);
      }
      u = end;
    }
  }
}

float grazingReach(float cosine, const RimAllowanceSettings& s) {
  if (!(s.reach > 0.0f) || !(cosine > 0.0f)) return s.truncation;
  return std::min(s.reach_max, std::max(s.truncation, s.reach / cosine));
}

DP_AVX2_CLONES
void rimAllowances(const float* depth, const float* inverse, const std::uint8_t* seeds,
                   SeedDistances* distances, const float* cosine, std::size_t pixels,
                   float metres_per_px, const RimAllowanceSettings& s, float* allowed) {
  // The nearest rim's depth and incidence: from seedDistances when it was given those planes
  // (no gather), else gathered here.
  auto& planes = distances->seed_values;
  if (planes.size() != 2 || planes[0].size() < pixels || planes[1].size() < pixels) {
    planes.assign(2, std::vector<float>(pixels, SeedDistances::kNoSeed));
    for (std::size_t i = 0; i < pixels; ++i) {
      const std::int32_t seed = distances->seed[i];
      if (seed < 0) continue;
      planes[0][i] = depth[seed];
      planes[1][i] = cosine[seed];
    }
  }
  const float* squared_px = distances->squared.data();
  const float* rim_depth = planes[0].data();
  const float* rim_cosine = planes[1].data();
  // The settings in a local copy: the stores below could otherwise alias them for the compiler.
  const RimAllowanceSettings local = s;
  const float scale = s.rim_scale * metres_per_px;
  for (std::size_t i = 0; i < pixels; ++i) {
    allowed[i] = rimAllowance(squared_px[i], depth[i], cosine[i], rim_depth[i], rim_cosine[i],
                              seeds[i] != 0, inverse[i] != 0.0f, scale, local);
  }
}

}  // namespace downstream_perception
