#include "downstream_perception/core/tsdf/depth_incidence.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

#include "downstream_perception/core/parallel/avx2_clones.h"
#include "downstream_perception/core/tsdf/tsdf_integrator.h"

namespace downstream_perception {

float incidenceCosine(const PinholeCamera& camera, const float* depth, const float* inverse, int u,
                      int v, float jump, float plane_tol) {
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
  // The tangent towards the neighbour (either side) nearest in depth, within `jump`, or, with
  // plane_tol > 0, beyond it where the pixel and both neighbours lie on one plane: far away at
  // grazing incidence a surface steps by more than jump per pixel.
  const auto tangent = [&](int du, int dv, Eigen::Vector3f* t) {
    float best = jump;
    bool found = false;
    const int u0 = u - du, v0 = v - dv, u1 = u + du, v1 = v + dv;
    if (u0 >= 0 && v0 >= 0 && u1 < w && v1 < h) {
      const std::size_t j0 = static_cast<std::size_t>(v0) * w + u0;
      const std::size_t j1 = static_cast<std::size_t>(v1) * w + u1;
      // Inverse depth is affine along an image line on a plane: 2 / d - 1 / d0 predicts 1 / d1.
      if (plane_tol > 0.0f && inverse[j0] != 0.0f && inverse[j1] != 0.0f &&
          predictsDepth(2.0f * inverse[i] - inverse[j0], depth[j1], plane_tol)) {
        best = std::numeric_limits<float>::infinity();
      }
    }
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

namespace {

/// c ? a : b on the bits: GCC would turn the select into masked loads of a's operands, which
/// its vectoriser then refuses; this way every load happens and the loop vectorises.
[[gnu::always_inline]] inline float pick(bool c, float a, float b) {
  std::uint32_t ai, bi;
  std::memcpy(&ai, &a, sizeof ai);
  std::memcpy(&bi, &b, sizeof bi);
  const std::uint32_t mask = 0u - static_cast<std::uint32_t>(c);
  const std::uint32_t bits = (ai & mask) | (bi & ~mask);
  float out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}

/// Where window_bad[u] is 0: slope_x[u] = (right[u] - left[u]) * scale_x, slope_y[u] =
/// (bottom[u] - top[u]) * scale_y, found[u] = 1; for u in [first, end). The buffers are
/// distinct (restrict): GCC would otherwise need more alias checks than it makes to vectorise.
[[gnu::always_inline]] inline void takeCleanSlopes(
    int first, int end, const std::uint8_t* __restrict window_bad, const float* __restrict right,
    const float* __restrict left, const float* __restrict bottom, const float* __restrict top,
    float scale_x, float scale_y, float* __restrict slope_x, float* __restrict slope_y,
    std::int32_t* __restrict found) {
  for (int u = first; u < end; ++u) {
    const bool clean = window_bad[u] == 0;
    slope_x[u] = pick(clean, (right[u] - left[u]) * scale_x, slope_x[u]);
    slope_y[u] = pick(clean, (bottom[u] - top[u]) * scale_y, slope_y[u]);
    found[u] = found[u] | static_cast<std::int32_t>(clean);
  }
}

/// The windows' radii, smallest first: 1, half of `radius`, `radius` (without repeats).
int windowRadii(int radius, int radii[3]) {
  int count = 0;
  for (const int r : {1, (radius + 1) / 2, radius}) {
    if (count == 0 || r > radii[count - 1]) radii[count++] = r;
  }
  return count;
}

}  // namespace

// External linkage on purpose (DP_AVX2_CLONES): a function local to this file would have its
// clone chosen while the library loads, before a sanitizer's runtime is up.
namespace detail {

/// windowIncidenceCosines past the bad pixels. Every window sum is a plain sum (nothing drifts)
/// and the radii nest: a larger window's sum is the smaller one's plus its outer rows (or
/// columns). Each loop runs along a row, so it vectorises.
DP_AVX2_CLONES
void windowCosines(const PinholeCamera& camera, const float* inverse, const int* radii, int count,
                   IncidenceWindowScratch* s, float* cosine) {
  const int w = camera.width, h = camera.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const std::uint8_t* bad = s->bad.data();
  // Inverse depth summed across each radius's window along every row (plane k for radius k).
  float* across = s->across.data();
  for (int v = 0; v < h; ++v) {
    const float* x = inverse + static_cast<std::size_t>(v) * w;
    int inner = 0;
    const float* smaller = x;  // the previous radius's sums (radius 0: the values)
    for (int k = 0; k < count; ++k) {
      const int r = radii[k];
      float* out = across + k * n + static_cast<std::size_t>(v) * w;
      for (int u = r; u + r < w; ++u) out[u] = smaller[u];
      for (int j = inner + 1; j <= r; ++j) {
        for (int u = r; u + r < w; ++u) out[u] += x[u - j] + x[u + j];
      }
      smaller = out;
      inner = r;
    }
  }
  float* down = s->down.data();                 // count rows of w: sums down each window's rows
  std::uint8_t* down_bad = s->down_bad.data();  // and its bad pixels (at most 129: fits)
  std::uint8_t* window_bad = s->window_bad.data();
  float* slope_x = s->slope_x.data();
  float* slope_y = s->slope_y.data();
  std::int32_t* found = s->found.data();
  const float inv_fx = static_cast<float>(1.0 / camera.fx);
  const float cx = static_cast<float>(camera.cx);
  for (int v = 0; v < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    std::fill(found, found + w, 0);
    int inner = 0;
    const float* smaller = inverse + row;
    const std::uint8_t* smaller_bad = bad + row;
    for (int k = 0; k < count; ++k) {
      const int r = radii[k];
      if (v - r < 0 || v + r >= h || 2 * r >= w) break;
      float* sums = down + static_cast<std::size_t>(k) * w;
      std::uint8_t* bads = down_bad + static_cast<std::size_t>(k) * w;
      std::copy(smaller, smaller + w, sums);
      std::copy(smaller_bad, smaller_bad + w, bads);
      for (int j = inner + 1; j <= r; ++j) {
        const float* above = inverse + row - static_cast<std::size_t>(j) * w;
        const float* below = inverse + row + static_cast<std::size_t>(j) * w;
        const std::uint8_t* bad_above = bad + row - static_cast<std::size_t>(j) * w;
        const std::uint8_t* bad_below = bad + row + static_cast<std::size_t>(j) * w;
        for (int u = 0; u < w; ++u) {
          sums[u] += above[u] + below[u];
          bads[u] = static_cast<std::uint8_t>(bads[u] + bad_above[u] + bad_below[u]);
        }
      }
      smaller = sums;
      smaller_bad = bads;
      inner = r;
      // Any bad pixel in the window: an OR across its columns.
      for (int u = r; u + r < w; ++u) window_bad[u] = bads[u - r];
      for (int j = 1 - r; j <= r; ++j) {
        for (int u = r; u + r < w; ++u) window_bad[u] |= bads[u + j];
      }
      // Row pairs' steps in a window sum to (2r + 1) rows of inverse depth at its right column
      // minus its left one; per unit of x = (u - cx) / fx that is over 2 r / fx. Column pairs'
      // steps likewise: its bottom row minus its top one. A larger clean window overrides.
      const float scale_x = static_cast<float>(camera.fx / ((2.0 * r + 1.0) * (2.0 * r)));
      const float scale_y = static_cast<float>(camera.fy / ((2.0 * r + 1.0) * (2.0 * r)));
      const float* across_row = across + k * n + row;
      takeCleanSlopes(
          r, w - r, window_bad, sums + r, sums - r, across_row + static_cast<std::size_t>(r) * w,
          across_row - static_cast<std::size_t>(r) * w, scale_x, scale_y, slope_x, slope_y, found);
    }
    if (inner == 0) continue;
    const float y = static_cast<float>((v - camera.cy) / camera.fy);
    const float* rho_row = inverse + row;
    float* out = cosine + row;
    for (int u = 0; u < w; ++u) {
      const float rho_x = slope_x[u], rho_y = slope_y[u], rho = rho_row[u];
      const float x = (static_cast<float>(u) - cx) * inv_fx;
      // On the plane n . X = d inverse depth is (n_x x + n_y y + n_z) / d: the normal is
      // (rho_x, rho_y, rho - rho_x x - rho_y y) times d, its product with the ray (x, y, 1)
      // rho times d.
      const float nz = rho - rho_x * x - rho_y * y;
      const float norms =
          std::sqrt(rho_x * rho_x + rho_y * rho_y + nz * nz) * std::sqrt(x * x + y * y + 1.0f);
      const float c = rho / norms;
      const bool use = (found[u] != 0) & (norms > 0.0f);
      out[u] = use ? (c < 1.0f ? c : 1.0f) : out[u];
    }
  }
}

}  // namespace detail

void windowIncidenceCosines(const PinholeCamera& camera, const float* depth, const float* inverse,
                            float jump, int radius, IncidenceWindowScratch* scratch,
                            float* cosine) {
  const int w = camera.width, h = camera.height;
  if (radius <= 0) return;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  int radii[3];
  const int count = windowRadii(radius, radii);
  // A pixel is bad where it is not valid or its pair with the next pixel along its row or its
  // column breaks the surface (depths more than `jump` apart); a window without bad pixels lies
  // on one surface (a pair leaving it counts too, one pixel stricter than needed, so that one
  // flag serves both directions).
  scratch->bad.resize(n);
  scratch->across.resize(static_cast<std::size_t>(count) * n);
  scratch->down.resize(static_cast<std::size_t>(count) * w);
  scratch->down_bad.resize(static_cast<std::size_t>(count) * w);
  for (auto* row_buffer : {&scratch->slope_x, &scratch->slope_y}) {
    row_buffer->assign(static_cast<std::size_t>(w), 0.0f);
  }
  scratch->window_bad.resize(static_cast<std::size_t>(w));
  scratch->found.resize(static_cast<std::size_t>(w));
  std::uint8_t* bad = scratch->bad.data();
  const auto breaks = [jump](float rho_a, float rho_b, float d_a, float d_b) {
    return (rho_b == 0.0f) | !(std::abs(d_b - d_a) <= jump) | (rho_a == 0.0f);
  };
  for (int v = 0; v < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const float* d = depth + row;
    const float* rho = inverse + row;
    std::uint8_t* out = bad + row;
    if (v + 1 < h) {
      for (int u = 0; u + 1 < w; ++u) {
        out[u] =
            breaks(rho[u], rho[u + 1], d[u], d[u + 1]) | breaks(rho[u], rho[u + w], d[u], d[u + w]);
      }
      out[w - 1] = breaks(rho[w - 1], rho[2 * w - 1], d[w - 1], d[2 * w - 1]);
    } else {
      for (int u = 0; u + 1 < w; ++u) out[u] = breaks(rho[u], rho[u + 1], d[u], d[u + 1]);
      out[w - 1] = rho[w - 1] == 0.0f;
    }
  }
  detail::windowCosines(camera, inverse, radii, count, scratch, cosine);
}

}  // namespace downstream_perception
