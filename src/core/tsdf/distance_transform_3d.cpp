#include "downstream_perception/core/tsdf/distance_transform_3d.h"

#include "downstream_perception/core/parallel/avx2_clones.h"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>

namespace downstream_perception {

namespace {

// Passes 2 and 3 by the brute-force window run in 16-bit integers: a squared distance within
// reach plus a window's k^2 stays below 2 r^2 + 2, which fits up to r = kEdtMaxRadius16. The
// window's cost grows with r (2 r + 1 taps per voxel), the envelope's does not, but 16 lanes a
// vector win in 3-D throughout: on the room's ESDF updates (one thread) 2.9x faster than the
// envelope at r = 21, 1.2x at r = 101, the ESDF's largest.
static_assert(2 * kEdtMaxRadius16 * kEdtMaxRadius16 + 1 <= std::numeric_limits<std::int16_t>::max(),
              "the window's sums must fit 16 bits");
/// Radii up to which 32-bit results, which only the band ESDF's 2-D transform asks for, take the
/// window, measured there (the room's band at 2 cm against the envelope): 7 % faster at r = 40,
/// even at 64, 10 % slower at 100.
constexpr int kWindowMaxRadius32 = 64;

using Narrow = std::int16_t;

/// One line of the separable transform: d[i] = min_k (i - k)^2 + f[k] over the lower envelope
/// of the parabolas rooted at the k with f[k] <= cap2; results above cap2 become kEdtFarSquared
/// (a farther seed can only be farther still after the next pass adds its own term).
struct LowerEnvelope {
  std::vector<int> hull;
  std::vector<double> bound;
  std::vector<std::int32_t> line;

  void resize(int n) {
    hull.resize(n);
    bound.resize(n + 1);
    line.resize(n);
  }

  /// Transforms `line` (length n) into d[i * stride] (i < n).
  void run(int n, std::int32_t cap2, std::int32_t* d, std::ptrdiff_t stride) {
    const auto f = [this](int k) { return static_cast<std::int64_t>(line[k]); };
    int top = -1;  // index of the last parabola in the hull
    for (int q = 0; q < n; ++q) {
      if (line[q] > cap2) continue;
      double s = -std::numeric_limits<double>::infinity();
      while (top >= 0) {
        const int p = hull[top];
        s = static_cast<double>((f(q) + std::int64_t{q} * q) - (f(p) + std::int64_t{p} * p)) /
            (2.0 * (q - p));
        if (s > bound[top]) break;
        --top;
      }
      ++top;
      hull[top] = q;
      bound[top] = top == 0 ? -std::numeric_limits<double>::infinity() : s;
      bound[top + 1] = std::numeric_limits<double>::infinity();
    }
    if (top < 0) {
      for (int i = 0; i < n; ++i) d[i * stride] = kEdtFarSquared;
      return;
    }
    int j = 0;
    for (int i = 0; i < n; ++i) {
      while (bound[j + 1] < i) ++j;
      const std::int64_t di = i - hull[j];
      const std::int64_t d2 = di * di + f(hull[j]);
      d[i * stride] = d2 <= cap2 ? static_cast<std::int32_t>(d2) : kEdtFarSquared;
    }
  }
};

}  // namespace

// External linkage on purpose (DP_AVX2_CLONES): a function local to this file would have its
// clone chosen while the library loads, before a sanitizer's runtime is up. Every loop runs
// along a row of x (or a plane), so it vectorises.
namespace detail {

/// Pass 1: squared distance along z (nz planes of `plane` voxels) to the nearest voxel labelled
/// `seed` in the same column; `far_squared` from `far` voxels on. `run` holds a plane.
template <typename T>
[[gnu::always_inline]] inline void columnPass(const std::uint8_t* labels, std::size_t plane, int nz,
                                              std::uint8_t seed, T far, T far_squared, T* run,
                                              T* out) {
  std::fill(run, run + plane, far);
  for (int z = 0; z < nz; ++z) {
    const std::uint8_t* l = labels + plane * z;
    T* oz = out + plane * z;
    for (std::size_t i = 0; i < plane; ++i) {
      run[i] = l[i] == seed ? T{0} : std::min(static_cast<T>(run[i] + 1), far);
      oz[i] = run[i];
    }
  }
  std::fill(run, run + plane, far);
  for (int z = nz - 1; z >= 0; --z) {
    const std::uint8_t* l = labels + plane * z;
    T* oz = out + plane * z;
    for (std::size_t i = 0; i < plane; ++i) {
      run[i] = l[i] == seed ? T{0} : std::min(static_cast<T>(run[i] + 1), far);
      const T g = std::min(oz[i], run[i]);
      oz[i] = g < far ? static_cast<T>(g * g) : far_squared;
    }
  }
}

DP_AVX2_CLONES
void columnPassWide(const std::uint8_t* labels, std::size_t plane, int nz, std::uint8_t seed,
                    std::int32_t far, std::int32_t* run, std::int32_t* out) {
  columnPass<std::int32_t>(labels, plane, nz, seed, far, kEdtFarSquared, run, out);
}

DP_AVX2_CLONES
void columnPassNarrow(const std::uint8_t* labels, std::size_t plane, int nz, std::uint8_t seed,
                      Narrow far, Narrow far_squared, Narrow* run, Narrow* out) {
  columnPass<Narrow>(labels, plane, nz, seed, far, far_squared, run, out);
}

/// Whether the n values hold a seed within reach (<= cap2) and a non-seed (> 0): else a pass
/// leaves them as they are.
template <typename T>
[[gnu::always_inline]] inline bool needsPass(const T* v, std::size_t n, T cap2) {
  T lo = std::numeric_limits<T>::max(), hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = std::min(lo, v[i]);
    hi = std::max(hi, v[i]);
  }
  return lo <= cap2 && hi > 0;
}

DP_AVX2_CLONES
bool needsPassWide(const std::int32_t* v, std::size_t n, std::int32_t cap2) {
  return needsPass(v, n, cap2);
}

DP_AVX2_CLONES
bool needsPassNarrow(const Narrow* v, std::size_t n, Narrow cap2) {
  return needsPass(v, n, cap2);
}

/// Row width of the y pass's input: whole chunks.
constexpr int kAcrossChunk = 32;

/// The y pass within radius r, by brute force over the 2 r + 1 rows around each row: row y of
/// `out` (nx wide) = min over |k| <= r of row y + k of `in` (a z plane of ny rows, `stride` a
/// multiple of kAcrossChunk wide, padded with far_squared) + k^2, above cap2 `far_squared`. A row
/// whose smallest value + k^2 exceeds cap2 cannot lower anything (the result would be capped):
/// skipped, which in sparse regions is most of them. `row_min` holds ny values.
DP_AVX2_CLONES
void windowPassAcrossRows(const Narrow* in, int stride, int nx, int ny, int r, Narrow cap2,
                          Narrow far_squared, Narrow* row_min, Narrow* out) {
  for (int y = 0; y < ny; ++y) {
    const Narrow* row = in + static_cast<std::size_t>(y) * stride;
    Narrow lo = far_squared;
    for (int x = 0; x < stride; ++x) lo = std::min(lo, row[x]);
    row_min[y] = lo;
  }
  // A chunk of a row at a time, its minima held in registers across the 2 r taps (a whole row
  // would be loaded and stored again at every tap).
  for (int y = 0; y < ny; ++y) {
    for (int x0 = 0; x0 < nx; x0 += kAcrossChunk) {
      Narrow acc[kAcrossChunk];
      const Narrow* centre = in + static_cast<std::size_t>(y) * stride + x0;
      for (int i = 0; i < kAcrossChunk; ++i) acc[i] = centre[i];
      for (int k = 1; k <= r; ++k) {
        const auto kk = static_cast<Narrow>(k * k);
        for (const int source : {y - k, y + k}) {
          if (source < 0 || source >= ny || row_min[source] > cap2 - kk) continue;
          const Narrow* a = in + static_cast<std::size_t>(source) * stride + x0;
          for (int i = 0; i < kAcrossChunk; ++i) {
            acc[i] = std::min(acc[i], static_cast<Narrow>(a[i] + kk));
          }
        }
      }
      Narrow* o = out + static_cast<std::size_t>(y) * nx + x0;
      const int n = std::min(kAcrossChunk, nx - x0);
      for (int i = 0; i < n; ++i) o[i] = acc[i] > cap2 ? far_squared : acc[i];
    }
  }
}

/// The x pass within radius r over one row: out[x] = min over |k| <= r of padded[r + x + k] +
/// k^2 (`padded`: the row with r `far_squared` values on each side), above cap2 far_squared.
DP_AVX2_CLONES
void windowPassAlongRow(const Narrow* padded, int n, int r, Narrow cap2, Narrow far_squared,
                        Narrow* out) {
  const Narrow* centre = padded + r;
  std::copy(centre, centre + n, out);
  for (int k = 1; k <= r; ++k) {
    const auto kk = static_cast<Narrow>(k * k);
    const Narrow* left = centre - k;
    const Narrow* right = centre + k;
    for (int x = 0; x < n; ++x) {
      out[x] = std::min(out[x], static_cast<Narrow>(std::min(left[x], right[x]) + kk));
    }
  }
  for (int x = 0; x < n; ++x) out[x] = out[x] > cap2 ? far_squared : out[x];
}

/// The window's results in an output's terms: above cap2 kEdtFarSquared (32 bits) ...
DP_AVX2_CLONES
void widen(const Narrow* v, std::size_t n, Narrow cap2, std::int32_t* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = v[i] > cap2 ? kEdtFarSquared : std::int32_t{v[i]};
}

/// ... or kEdtFarSquared16 (16 bits, in place).
DP_AVX2_CLONES
void markFar(std::size_t n, Narrow cap2, Narrow* v) {
  for (std::size_t i = 0; i < n; ++i) v[i] = v[i] > cap2 ? kEdtFarSquared16 : v[i];
}

}  // namespace detail

namespace {

/// All three passes in 16 bits (r <= kEdtMaxRadius16), passes 2 and 3 by the window, in
/// `narrow` (the box's voxels): squared distances up to cap2 = r^2, r^2 + 1 beyond.
void windowTransform(const std::uint8_t* labels, int nx, int ny, int nz, std::uint8_t seed_label,
                     int r, Narrow* narrow, EdtScratch* scratch) {
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  const auto cap2 = static_cast<Narrow>(r * r);
  const auto far_squared = static_cast<Narrow>(r * r + 1);
  scratch->narrow_plane.resize(plane);  // pass 1's running counts, then pass 2's input
  detail::columnPassNarrow(labels, plane, nz, seed_label, static_cast<Narrow>(r + 1), far_squared,
                           scratch->narrow_plane.data(), narrow);
  // narrow_row: the y pass's row minima (ny), then the x pass's padded row (nx + 2 r).
  scratch->narrow_row.resize(
      std::max(static_cast<std::size_t>(ny),
               static_cast<std::size_t>(nx) + 2 * static_cast<std::size_t>(r)));
  // Pass 2 (y): each z plane (it stays in cache), from a copy whose rows are padded to whole
  // chunks.
  const int stride = (nx + detail::kAcrossChunk - 1) / detail::kAcrossChunk * detail::kAcrossChunk;
  scratch->narrow_plane.assign(static_cast<std::size_t>(stride) * ny, far_squared);
  for (int z = 0; z < nz; ++z) {
    Narrow* oz = narrow + plane * z;
    if (!detail::needsPassNarrow(oz, plane, cap2)) continue;
    for (int y = 0; y < ny; ++y) {
      std::copy(oz + static_cast<std::size_t>(y) * nx, oz + static_cast<std::size_t>(y + 1) * nx,
                scratch->narrow_plane.begin() + static_cast<std::ptrdiff_t>(y) * stride);
    }
    detail::windowPassAcrossRows(scratch->narrow_plane.data(), stride, nx, ny, r, cap2, far_squared,
                                 scratch->narrow_row.data(), oz);
  }
  // Pass 3 (x): each row, from a copy padded with far values.
  Narrow* padded = scratch->narrow_row.data();
  std::fill(padded, padded + r, far_squared);
  std::fill(padded + r + nx, padded + 2 * r + nx, far_squared);
  for (std::size_t row = 0; row < plane / nx * nz; ++row) {
    Narrow* line = narrow + row * nx;
    if (!detail::needsPassNarrow(line, nx, cap2)) continue;
    std::copy(line, line + nx, padded + r);
    detail::windowPassAlongRow(padded, nx, r, cap2, far_squared, line);
  }
}

/// Passes 2 and 3 by the lower envelope, in 32 bits (any radius).
void envelopeTransform(const std::uint8_t* labels, int nx, int ny, int nz, std::uint8_t seed_label,
                       int r, std::int32_t* o, EdtScratch* scratch) {
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  const std::int32_t cap2 = r * r;
  scratch->run.resize(plane);
  detail::columnPassWide(labels, plane, nz, seed_label, r + 1, scratch->run.data(), o);
  LowerEnvelope envelope;
  envelope.resize(std::max({nx, ny, nz}));
  // Pass 2 (y): each column of each z plane (the plane stays in cache).
  for (int z = 0; z < nz; ++z) {
    std::int32_t* oz = o + plane * z;
    for (int x = 0; x < nx; ++x) {
      bool any_seed = false, any_positive = false;
      for (int y = 0; y < ny; ++y) {
        const std::int32_t v = oz[x + static_cast<std::size_t>(y) * nx];
        envelope.line[y] = v;
        any_seed |= v <= cap2;
        any_positive |= v > 0;
      }
      if (any_seed && any_positive) envelope.run(ny, cap2, oz + x, nx);
    }
  }
  // Pass 3 (x): each row.
  for (std::size_t row = 0; row < plane / nx * nz; ++row) {
    std::int32_t* line = o + row * nx;
    if (!detail::needsPassWide(line, nx, cap2)) continue;
    std::copy(line, line + nx, envelope.line.begin());
    envelope.run(nx, cap2, line, 1);
  }
}

/// Resizes `out` to the box of `size` voxels; false (and `out` empty) for an empty box.
template <typename T>
bool fitToBox(const Eigen::Vector3i& size, std::vector<T>* out) {
  if ((size.array() <= 0).any()) {
    out->clear();
    return false;
  }
  out->resize(static_cast<std::size_t>(size.x()) * size.y() * size.z());
  return true;
}

}  // namespace

std::size_t EdtScratch::bytes() const {
  return run.capacity() * sizeof(std::int32_t) +
         (narrow.capacity() + narrow_plane.capacity() + narrow_row.capacity()) * sizeof(Narrow);
}

// Pass 1 (z) by running counts along the columns, swept plane by plane so memory is read in
// order; passes 2 (y) and 3 (x) by a brute-force window over the 2 r + 1 neighbours in 16 bits
// up to kWindowMaxRadius32 (32-bit results) or kEdtMaxRadius16 (16-bit), by the lower envelope
// beyond. Either way a line (or plane) that is all seeds (0) or has no seed within reach stays
// as it is: with dense seeds (free space, for the distances of occupied voxels) most are
// skipped.
void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int32_t>* out, EdtScratch* scratch) {
  if (!fitToBox(size, out)) return;
  const int r = std::max(0, max_distance_voxels);
  if (r > kWindowMaxRadius32) {
    envelopeTransform(labels, size.x(), size.y(), size.z(), seed_label, r, out->data(), scratch);
    return;
  }
  scratch->narrow.resize(out->size());
  windowTransform(labels, size.x(), size.y(), size.z(), seed_label, r, scratch->narrow.data(),
                  scratch);
  detail::widen(scratch->narrow.data(), out->size(), static_cast<Narrow>(r * r), out->data());
}

void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int16_t>* out, EdtScratch* scratch) {
  if (max_distance_voxels > kEdtMaxRadius16) {
    const std::string limit = std::to_string(kEdtMaxRadius16);
    throw std::invalid_argument(
        "boundedSquaredDistances3d: 16-bit results need a radius of at most " + limit +
        " voxels, got " + std::to_string(max_distance_voxels));
  }
  if (!fitToBox(size, out)) return;
  const int r = std::max(0, max_distance_voxels);
  windowTransform(labels, size.x(), size.y(), size.z(), seed_label, r, out->data(), scratch);
  detail::markFar(out->size(), static_cast<Narrow>(r * r), out->data());
}

}  // namespace downstream_perception
