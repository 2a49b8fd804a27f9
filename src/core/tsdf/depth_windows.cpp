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

/// The signed slope change across a window's two pixels p1, p2 along a line, from the pixels
/// before and after them: (p3 - p2) - (p1 - p0) in inverse depth, times z^2 (m): the whole kink
/// of a crease between p1 and p2 wherever it lies there (the windows beside it see a share of
/// it), 0 on a plane. 0 where a pixel is invalid or the four span more than max_step (m): no
/// evidence.
inline float slopeChange(const float* i, const float* d, std::ptrdiff_t step, float max_step) {
  const float p0 = i[-step], p1 = i[0], p2 = i[step], p3 = i[2 * step];
  const float d0 = d[-step], d1 = d[0], d2 = d[step], d3 = d[2 * step];
  const float lo = std::min(std::min(d0, d1), std::min(d2, d3));
  const float hi = std::max(std::max(d0, d1), std::max(d2, d3));
  const bool ok = (p0 != 0.0f) & (p1 != 0.0f) & (p2 != 0.0f) & (p3 != 0.0f) & (hi - lo <= max_step);
  return ok ? ((p3 - p2) - (p1 - p0)) * d1 * d1 : 0.0f;
}

/// One image row's slope changes: along the row (step 1, windows 1 .. w - 3) or, for a row v in
/// 1 .. h - 3, along the columns (step w); 0 elsewhere.
DP_AVX2_CLONES
void rowSlopeChanges(const float* inverse_row, const float* depth_row, int w, std::ptrdiff_t step,
                     float max_step, float* out) {
  const int first = step == 1 ? 1 : 0, last = step == 1 ? w - 3 : w - 1;
  std::fill(out, out + first, 0.0f);
  for (int u = first; u <= last; ++u) {
    out[u] = slopeChange(inverse_row + u, depth_row + u, step, max_step);
  }
  std::fill(out + last + 1, out + w, 0.0f);
}

/// out[u] = the sum of in[u - r .. u + 1 + r] (clipped to the row).
DP_AVX2_CLONES
void boxSumRow(const float* in, int w, int r, float* out) {
  std::fill(out, out + w, 0.0f);
  for (int k = -r; k <= r + 1; ++k) {
    const int lo = std::max(0, -k), hi = std::min(w, w - k);
    for (int u = lo; u < hi; ++u) out[u] += in[u + k];
  }
}

/// Windows read as one plane whose summed slope change (summedSlopeChanges) exceeds the threshold
/// and is the largest across the crease (the windows beside it see a share of it) become
/// creases of that direction (the larger excess if both). rows: summed along the rows' slope
/// changes (a crease between the window's columns); columns: the columns' (between its rows).
DP_AVX2_CLONES
void addSummedCreases(const float* rows, const float* columns, int w, int h, float row_threshold,
                      float column_threshold, DepthWindow* out) {
  const float row_scale = 1.0f / row_threshold, column_scale = 1.0f / column_threshold;
  for (int v = 1; v + 2 < h; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * w;
    const float* r = rows + row;
    const float* c = columns + row;
    std::uint8_t* classes = reinterpret_cast<std::uint8_t*>(out + row);
    for (int u = 1; u + 2 < w; ++u) {
      const float rr = std::abs(r[u]) * row_scale, cc = std::abs(c[u]) * column_scale;
      const bool across_columns = (rr > 1.0f) & (rr >= std::abs(r[u - 1]) * row_scale) &
                                  (rr > std::abs(r[u + 1]) * row_scale);
      const bool across_rows = (cc > 1.0f) & (cc >= std::abs(c[u - w]) * column_scale) &
                               (cc > std::abs(c[u + w]) * column_scale);
      const std::uint8_t crease = (across_columns & (rr >= cc)) | !across_rows ? 3 : 2;
      const bool plane = classes[u] == 1;
      classes[u] = plane & (across_columns | across_rows) ? crease : classes[u];
    }
  }
}

}  // namespace detail

namespace {

/// The windows' slope changes summed along the crease, row by row (the kink buffers are free
/// once the windows are classified): rows[v] sums the row slope changes of lines v - r .. v + 1
/// + r (a running sum over a ring of the last 2 r + 3 lines: the line entering added, the one
/// leaving taken off; rounding drifts by ~1e-7 of the sums over an image, far below the
/// noise), columns[v] the column slope changes of row v over columns u - r .. u + 1 + r. A
/// crease running along the lines adds up, depth noise only as the square root.
void summedSlopeChanges(const float* depth, const float* inverse, int w, int h, float max_step,
                        int r, DepthWindowScratch* scratch, float* rows, float* columns) {
  const int slots = 2 * r + 3;
  const std::size_t width = static_cast<std::size_t>(w);
  scratch->line_ring.resize(static_cast<std::size_t>(slots) * width);
  scratch->line.resize(width);
  const auto line = [&](int k) {  // row k's row slope changes, kept in the ring
    float* slot = scratch->line_ring.data() + static_cast<std::size_t>(k % slots) * width;
    const std::size_t at = static_cast<std::size_t>(k) * width;
    detail::rowSlopeChanges(inverse + at, depth + at, w, 1, max_step, slot);
    return slot;
  };
  for (int v = 0; v < h; ++v) {
    float* o = rows + static_cast<std::size_t>(v) * width;
    if (v == 0) {
      std::fill(o, o + w, 0.0f);
      for (int k = 0; k < std::min(h, r + 2); ++k) {
        const float* c = line(k);
        for (int u = 0; u < w; ++u) o[u] += c[u];
      }
    } else {
      std::copy(o - width, o, o);
      const int enter = v + 1 + r, leave = v - r - 1;
      if (enter < h) {
        const float* c = line(enter);
        for (int u = 0; u < w; ++u) o[u] += c[u];
      }
      if (leave >= 0) {
        const float* c =
            scratch->line_ring.data() + static_cast<std::size_t>(leave % slots) * width;
        for (int u = 0; u < w; ++u) o[u] -= c[u];
      }
    }
    float* column_row = columns + static_cast<std::size_t>(v) * width;
    if (v >= 1 && v + 3 <= h) {
      const std::size_t at = static_cast<std::size_t>(v) * width;
      detail::rowSlopeChanges(inverse + at, depth + at, w, w, max_step, scratch->line.data());
      detail::boxSumRow(scratch->line.data(), w, r, column_row);
    } else {
      std::fill(column_row, column_row + w, 0.0f);
    }
  }
}

/// max(floor, factor x the median of `sample`) (floor if empty); reorders the sample.
float medianThreshold(std::vector<float>* sample, float factor, float floor) {
  if (sample->empty()) return floor;
  const auto middle = sample->begin() + static_cast<std::ptrdiff_t>(sample->size() / 2);
  std::nth_element(sample->begin(), middle, sample->end());
  return std::max(floor, factor * *middle);
}

/// medianThreshold of every kNoiseStride-th nonzero |value|.
float noiseThreshold(const float* values, std::size_t n, float factor, float floor,
                     std::vector<float>* sample) {
  sample->clear();
  for (std::size_t i = 0; i < n; i += kNoiseStride) {
    if (values[i] != 0.0f) sample->push_back(std::abs(values[i]));
  }
  return medianThreshold(sample, factor, floor);
}

}  // namespace

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
  const float threshold =
      medianThreshold(&sample, settings.crease_noise_factor, settings.crease_min);
  detail::classifyWindows(depth, inverse, kr, kc, w, h, settings.max_step, threshold, out);
  if (settings.crease_sum_radius > 0 && threshold > settings.crease_min && w >= 4 && h >= 4) {
    // Under depth noise (the threshold above the floor) a window's own kinks drown a crease;
    // summed along it over neighbouring lines it stands out again. Without noise they see every
    // crease, and the sums would only add windows beside slanting ones (the kink buffers are
    // free now).
    const int r = settings.crease_sum_radius;
    summedSlopeChanges(depth, inverse, w, h, settings.max_step, r, scratch,
                       scratch->kink_row.data(), scratch->kink_column.data());
    const float* rows = scratch->kink_row.data();
    const float* columns = scratch->kink_column.data();
    // A sum of 2 r + 2 slope changes, each twice a window's kink on a curved surface: the
    // floor asks of each line what the kinks' floor asks of a window.
    const float floor = settings.crease_min * static_cast<float>(2 * (2 * r + 2));
    const float row_threshold =
        noiseThreshold(rows, n, settings.crease_sum_noise_factor, floor, &scratch->sample);
    const float column_threshold =
        noiseThreshold(columns, n, settings.crease_sum_noise_factor, floor, &scratch->sample);
    detail::addSummedCreases(rows, columns, w, h, row_threshold, column_threshold, out);
  }
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
