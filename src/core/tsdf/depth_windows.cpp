#include "downstream_perception/core/tsdf/depth_windows.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "downstream_perception/core/parallel/avx2_clones.h"

namespace downstream_perception {

// External linkage on purpose (DP_AVX2_CLONES): a function local to this file would have its
// clone chosen while the library loads, before a sanitizer's runtime is up (ThreadSanitizer
// crashed there).
namespace detail {

/// |Second difference| of inverse depth through each pixel along its row (kink_row) and its
/// column (kink_column); 0 on the image's border. Not checked for depth edges or invalid
/// pixels here (a window uses the smaller kink of each pair, and creaseInverseDepth checks the
/// pixels it reads), so the loop is plain arithmetic the compiler vectorises.
DP_AVX2_CLONES
void pixelKinks(const float* inverse, int w, int h, float* kink_row, float* kink_column) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  std::fill(kink_row, kink_row + w, 0.0f);
  std::fill(kink_column, kink_column + w, 0.0f);
  std::fill(kink_row + n - w, kink_row + n, 0.0f);
  std::fill(kink_column + n - w, kink_column + n, 0.0f);
  for (int v = 1; v + 1 < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const float* i = inverse + row;
    float* out_row = kink_row + row;
    float* out_column = kink_column + row;
    for (int u = 1; u + 1 < w; ++u) {
      out_row[u] = std::abs(i[u - 1] - 2.0f * i[u] + i[u + 1]);
      out_column[u] = std::abs(i[u - w] - 2.0f * i[u] + i[u + w]);
    }
    out_row[0] = out_row[w - 1] = out_column[0] = out_column[w - 1] = 0.0f;
  }
}

/// The bend of the window from pixel i (right, down) and on which side its crease lies, or -1
/// (bend) for a window that is not continuous (an invalid pixel or a step over max_step): the
/// largest of its twist, |i00 + i11 - i10 - i01| / 4 (how far the bilinear interpolation at its
/// centre lies from either triangle's plane), and, along each of its two rows and two columns,
/// the smaller kink of its two pixels there, in inverse depth, times z^2 (m). A crease between
/// the two pixels, a share s of the way, kinks them by k (1 - s) and k s, and the interpolation
/// between them errs by k s (1 - s), at most the smaller; a crease beside the window kinks one
/// of them only (the window itself lies on one plane). The kinks see creases along the rows and
/// columns, to which the twist is blind. Inline: the classification's loop vectorises.
struct WindowBend {
  float bend;
  bool between_rows;  ///< bent more across its rows than across its columns
};

inline WindowBend windowBend(const float* depth, const float* inverse, const float* kink_row,
                             const float* kink_column, std::size_t i, std::size_t w,
                             float max_step) {
  const float* d = depth + i;
  const float* inv = inverse + i;
  const float* kr = kink_row + i;
  const float* kc = kink_column + i;
  const float lo = std::min(std::min(d[0], d[1]), std::min(d[w], d[w + 1]));
  const float hi = std::max(std::max(d[0], d[1]), std::max(d[w], d[w + 1]));
  const bool continuous = (inv[0] != 0.0f) & (inv[1] != 0.0f) & (inv[w] != 0.0f) &
                          (inv[w + 1] != 0.0f) & (hi - lo <= max_step);
  const float twist = 0.25f * std::abs(inv[0] + inv[w + 1] - inv[1] - inv[w]);
  const float across_columns = std::max(std::min(kr[0], kr[1]), std::min(kr[w], kr[w + 1]));
  const float across_rows = std::max(std::min(kc[0], kc[w]), std::min(kc[1], kc[w + 1]));
  const float bend = std::max(twist, std::max(across_rows, across_columns)) * hi * hi;
  return {continuous ? bend : -1.0f, across_rows >= across_columns};
}

/// Every window's class, given the threshold (the image's last row and column: none).
DP_AVX2_CLONES
void classifyWindows(const float* depth, const float* inverse, const float* kink_row,
                     const float* kink_column, int w, int h, float max_step, float threshold,
                     DepthWindow* out) {
  const std::size_t stride = static_cast<std::size_t>(w);
  for (int v = 0; v + 1 < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    std::uint8_t* classes = reinterpret_cast<std::uint8_t*>(out + row);
    for (int u = 0; u + 1 < w; ++u) {
      const WindowBend b =
          windowBend(depth, inverse, kink_row, kink_column, row + u, stride, max_step);
      const std::uint8_t crease = b.between_rows ? 2 : 3;
      classes[u] = !(b.bend >= 0.0f) ? 0 : (b.bend <= threshold ? 1 : crease);
    }
    classes[w - 1] = 0;
  }
  std::fill(out + static_cast<std::size_t>(h > 0 ? h - 1 : 0) * w,
            out + static_cast<std::size_t>(h) * w, DepthWindow::kNearestPixel);
}

}  // namespace detail

float classifyDepthWindows(const float* depth, const float* inverse, int w, int h,
                           const DepthWindowSettings& settings, DepthWindowScratch* scratch,
                           DepthWindow* out) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  if (w < 2 || h < 2) {
    std::fill(out, out + n, DepthWindow::kNearestPixel);
    return settings.crease_min;
  }
  scratch->kink_row.resize(n);
  scratch->kink_column.resize(n);
  const float* kr = scratch->kink_row.data();
  const float* kc = scratch->kink_column.data();
  detail::pixelKinks(inverse, w, h, scratch->kink_row.data(), scratch->kink_column.data());
  // The noise level from a sample of the windows (the last row and column hold none).
  std::vector<float>& sample = scratch->sample;
  sample.clear();
  const std::size_t stride = static_cast<std::size_t>(w);
  for (std::size_t i = 0; i < n - stride; i += kNoiseStride) {
    if (i % stride == stride - 1) continue;
    const float bend =
        detail::windowBend(depth, inverse, kr, kc, i, stride, settings.max_step).bend;
    if (bend >= 0.0f) sample.push_back(bend);
  }
  float threshold = settings.crease_min;
  if (!sample.empty()) {
    const auto middle = sample.begin() + static_cast<std::ptrdiff_t>(sample.size() / 2);
    std::nth_element(sample.begin(), middle, sample.end());
    threshold = std::max(threshold, settings.crease_noise_factor * *middle);
  }
  detail::classifyWindows(depth, inverse, kr, kc, w, h, settings.max_step, threshold, out);
  return threshold;
}

CreaseDepth creaseInverseDepth(const float* inverse, int w, int h, int u0, int v0, float a, float b,
                               DepthWindow kind, float max_step) {
  const bool between_rows = kind == DepthWindow::kCreaseBetweenRows;
  // Along the crossing direction: step (pixels) and the window's first index there.
  const int first = between_rows ? v0 : u0, size = between_rows ? h : w;
  if (first < 1 || first + 2 >= size) return {};
  const std::ptrdiff_t step = between_rows ? w : 1, side = between_rows ? 1 : w;
  const float t = between_rows ? b : a, s = between_rows ? a : b;
  // Each side's plane, extended to (a, b): in each of the window's two lines across the crease,
  // the line through that side's two pixels, then linear between the lines (on a plane inverse
  // depth is affine in the image). The two planes are compared at (a, b) itself, not line by
  // line: a crease slanting across the window meets the two lines at different places.
  float near_side = 0.0f, far_side = 0.0f, curvature = 0.0f;
  for (int k = 0; k < 2; ++k) {
    const float* q = inverse + static_cast<std::ptrdiff_t>(v0) * w + u0 + k * side;
    const float p0 = q[-step], p1 = q[0], p2 = q[step], p3 = q[2 * step];
    if (!(p0 != 0.0f && p1 != 0.0f && p2 != 0.0f && p3 != 0.0f)) return {};
    // The outer pixels on their sides' surfaces, not across a depth edge (the window's own
    // four are within max_step of each other).
    if (!(std::abs(1.0f / p0 - 1.0f / p1) <= max_step &&
          std::abs(1.0f / p3 - 1.0f / p2) <= max_step)) {
      return {};
    }
    const float weight = k == 0 ? 1.0f - s : s;
    near_side += weight * (p1 + t * (p1 - p0));
    far_side += weight * (p2 + (t - 1.0f) * (p3 - p2));
    curvature += (p0 - 2.0f * p1 + p2) + (p1 - 2.0f * p2 + p3);
  }
  // Inverse depth is convex across a concave crease (the surface seen is the nearer plane).
  CreaseDepth crease;
  crease.concave = curvature > 0.0f;
  crease.inverse = crease.concave ? std::max(near_side, far_side) : std::min(near_side, far_side);
  return crease;
}

}  // namespace downstream_perception
