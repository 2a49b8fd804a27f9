#include "downstream_perception/core/tsdf/depth_rims.h"

#include <Eigen/Core>

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

float incidenceCosine(const PinholeCamera& camera, const float* depth, const float* inverse, int u,
                      int v, float jump) {
  const int w = camera.width, h = camera.height;
  const float inv_fx = static_cast<float>(1.0 / camera.fx);
  const float inv_fy = static_cast<float>(1.0 / camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const auto point = [&](int uu, int vv, float d) {
    return Eigen::Vector3f((static_cast<float>(uu) - cx) * inv_fx * d,
                           (static_cast<float>(vv) - cy) * inv_fy * d, d);
  };
  const std::size_t i = static_cast<std::size_t>(v) * w + u;
  const float d = depth[i];
  const Eigen::Vector3f p = point(u, v, d);
  // The tangent towards the neighbour (either side) nearest in depth, within `jump`. Far away
  // at grazing incidence a surface steps by more than that per pixel: no estimate there. (Taking
  // a neighbour that continues a plane instead was tried: the grazing reach then ran past thin
  // boards' far edges into the gap behind them, a sampling the rims cannot see: ghosts 0.006 ->
  // 0.037 % median over the accuracy scenes.)
  const auto tangent = [&](int du, int dv, Eigen::Vector3f* t) {
    float best = jump;
    bool found = false;
    for (const int sign : {-1, 1}) {
      const int uu = u + sign * du, vv = v + sign * dv;
      if (uu < 0 || vv < 0 || uu >= w || vv >= h) continue;
      const std::size_t j = static_cast<std::size_t>(vv) * w + uu;
      const float diff = std::abs(depth[j] - d);
      if (inverse[j] == 0.0f || !(diff <= best)) continue;
      best = diff;
      *t = point(uu, vv, depth[j]) - p;
      found = true;
    }
    return found;
  };
  Eigen::Vector3f tu, tv;
  if (!tangent(1, 0, &tu) || !tangent(0, 1, &tv)) return -1.0f;
  const Eigen::Vector3f normal = tu.cross(tv);
  const float norms = normal.norm() * p.norm();
  if (!(norms > 0.0f)) return -1.0f;
  return std::min(1.0f, std::abs(normal.dot(p)) / norms);
}

void incidenceCosines(const PinholeCamera& camera, const float* depth, const float* inverse,
                      float jump, std::vector<float>* column_x, float* cosine) {
  const int w = camera.width, h = camera.height;
  column_x->resize(static_cast<std::size_t>(w));
  float* xs = column_x->data();
  for (int u = 0; u < w; ++u) xs[u] = static_cast<float>((u - camera.cx) / camera.fx);
  incidenceCosinesInterior(camera, depth, inverse, jump, xs, cosine);
  // The image's border pixels (one neighbour missing on a side) one at a time.
  for (int u = 0; u < w; ++u) {
    cosine[u] = incidenceCosine(camera, depth, inverse, u, 0, jump);
    const std::size_t last = static_cast<std::size_t>(h - 1) * w + u;
    cosine[last] = incidenceCosine(camera, depth, inverse, u, h - 1, jump);
  }
  for (int v = 1; v + 1 < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    cosine[row] = incidenceCosine(camera, depth, inverse, 0, v, jump);
    cosine[row + w - 1] = incidenceCosine(camera, depth, inverse, w - 1, v, jump);
  }
}

DP_AVX2_CLONES
void incidenceCosinesInterior(const PinholeCamera& camera, const float* depth, const float* inverse,
                              float jump, const float* xs, float* cosine) {
  const int w = camera.width, h = camera.height;
  // Branch-free (selects only) so the row loop vectorises; the same choices and arithmetic as
  // incidenceCosine, which the gtests compare it with.
  for (int v = 1; v + 1 < h; ++v) {
    const float y = static_cast<float>((v - camera.cy) / camera.fy);
    const float y_up = static_cast<float>((v - 1 - camera.cy) / camera.fy);
    const float y_down = static_cast<float>((v + 1 - camera.cy) / camera.fy);
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const float* d = depth + row;
    const float* iv = inverse + row;
    float* out = cosine + row;
    for (int u = 1; u + 1 < w; ++u) {
      const float dc = d[u];
      const float x = xs[u];
      // Along the row: the left neighbour if within jump, the right one if within jump and at
      // least as near in depth (incidenceCosine visits left, then right, keeping ties right).
      const float dl = d[u - 1], dr = d[u + 1];
      const float el = std::abs(dl - dc), er = std::abs(dr - dc);
      const bool okl = (iv[u - 1] != 0.0f) & (el <= jump);
      const bool okr = (iv[u + 1] != 0.0f) & (er <= jump);
      const bool right = okr & (!okl | (er <= el));
      const float dh = right ? dr : dl;
      const float xh = right ? xs[u + 1] : xs[u - 1];
      const float tux = xh * dh - x * dc, tuy = y * dh - y * dc, tuz = dh - dc;
      // Along the column: up, then down.
      const float du = d[u - w], dd = d[u + w];
      const float eu = std::abs(du - dc), ed = std::abs(dd - dc);
      const bool oku = (iv[u - w] != 0.0f) & (eu <= jump);
      const bool okd = (iv[u + w] != 0.0f) & (ed <= jump);
      const bool down = okd & (!oku | (ed <= eu));
      const float dvv = down ? dd : du;
      const float yv = down ? y_down : y_up;
      const float tvx = x * dvv - x * dc, tvy = yv * dvv - y * dc, tvz = dvv - dc;
      const float nx = tuy * tvz - tuz * tvy;
      const float ny = tuz * tvx - tux * tvz;
      const float nz = tux * tvy - tuy * tvx;
      const float px = x * dc, py = y * dc, pz = dc;
      const float norms =
          std::sqrt(nx * nx + ny * ny + nz * nz) * std::sqrt(px * px + py * py + pz * pz);
      const float c = std::min(1.0f, std::abs(nx * px + ny * py + nz * pz) / norms);
      const bool ok = (iv[u] != 0.0f) & (okl | okr) & (oku | okd) & (norms > 0.0f);
      out[u] = ok ? c : -1.0f;
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
  const float fallback_squared = s.fallback_radius_px * s.fallback_radius_px;
  // The settings in locals: the stores below could otherwise alias them for the compiler.
  const float voxel = s.voxel, mu = s.truncation, reach_per_cos = s.reach, reach_max = s.reach_max;
  const float jump = s.jump;
  const float scale = s.rim_scale * metres_per_px;
  const float radians_per_px = s.radians_per_px;
  const float margin = kSilhouetteSineMargin;
  const bool reaching = s.reach > 0.0f;
  for (std::size_t i = 0; i < pixels; ++i) {
    const float squared = squared_px[i], z = depth[i], c = cosine[i];
    const float rim_z = rim_depth[i], rc = rim_cosine[i];
    const bool is_seed = seeds[i] != 0, valid = inverse[i] != 0.0f;
    // The nearest rim counts only if this pixel is on its object (not the background beside
    // it, more than jump farther).
    const bool near_rim = (squared < SeedDistances::kNoSeed) & (z <= rim_z + jump);
    const float reach =
        reaching & (c > 0.0f) ? std::min(reach_max, std::max(mu, reach_per_cos / c)) : mu;
    const float sine = std::sqrt(std::max(0.0f, 1.0f - c * c));
    // A rim seen more grazing than the pixel (unknown incidence: grazing) ends a surface that
    // turns towards the line of sight: the silhouette of a convex surface, behind which the ray
    // leaves no earlier than at the silhouette's depth, sine (1 + sine) times the plane's travel
    // (a sphere: half its chord 2 r cos against r (1 - sine) / (cos sine); issue 22). On a plane
    // the incidences of two pixels differ by at most the angle between their rays (D px apart:
    // D radians_per_px), so only a rim more grazing than that (and the estimate's noise) turns.
    const float distance_px = std::sqrt(squared);
    const float rim_sine = rc < 0.0f ? 1.0f : std::sqrt(std::max(0.0f, 1.0f - rc * rc));
    // (Only read where near_rim: and-ing it in here kept the AVX2 copy from vectorising.)
    const bool turning = rim_sine > sine + distance_px * radians_per_px + margin;
    const float factor = turning ? std::max(1.0f, sine * (1.0f + sine)) : 1.0f;
    const float travel = factor * scale * distance_px * z / std::max(c * sine, 1e-6f);
    float a = near_rim ? std::min(reach, std::max(voxel, travel)) : reach;
    a = c < 0.0f ? (near_rim & (squared <= fallback_squared) ? voxel : mu) : a;
    a = is_seed ? voxel : a;
    allowed[i] = valid ? a : mu;
  }
}

}  // namespace downstream_perception
