#include "downstream_perception/core/tsdf/distance_transform_3d.h"

#include <algorithm>
#include <cstddef>
#include <limits>

namespace downstream_perception {

namespace {

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

void boundedSquaredDistances3d(const std::uint8_t* labels, const Eigen::Vector3i& size,
                               std::uint8_t seed_label, int max_distance_voxels,
                               std::vector<std::int32_t>* out, std::vector<std::int32_t>* scratch) {
  const int nx = size.x(), ny = size.y(), nz = size.z();
  if (nx <= 0 || ny <= 0 || nz <= 0) {
    out->clear();
    return;
  }
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  out->resize(plane * nz);
  std::int32_t* o = out->data();
  const std::int32_t far = max_distance_voxels + 1;
  const std::int32_t cap2 = max_distance_voxels * max_distance_voxels;

  // Pass 1 (z), swept plane by plane so memory is read in order: distance along z to the
  // nearest seed of the same (x, y) column, capped at `far`; then squared.
  std::vector<std::int32_t>& run = *scratch;
  run.assign(plane, far);
  for (int z = 0; z < nz; ++z) {
    const std::uint8_t* l = labels + plane * z;
    std::int32_t* oz = o + plane * z;
    for (std::size_t i = 0; i < plane; ++i) {
      run[i] = l[i] == seed_label ? 0 : std::min(run[i] + 1, far);
      oz[i] = run[i];
    }
  }
  std::fill(run.begin(), run.end(), far);
  for (int z = nz - 1; z >= 0; --z) {
    const std::uint8_t* l = labels + plane * z;
    std::int32_t* oz = o + plane * z;
    for (std::size_t i = 0; i < plane; ++i) {
      run[i] = l[i] == seed_label ? 0 : std::min(run[i] + 1, far);
      const std::int32_t g = std::min(oz[i], run[i]);
      oz[i] = g < far ? g * g : kEdtFarSquared;
    }
  }

  // A line that is all seeds (0) or has no seed within reach stays as it is: with dense seeds
  // (free space, for the distances of occupied voxels) most lines are skipped.
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
  for (std::size_t r = 0; r < plane / nx * nz; ++r) {
    std::int32_t* row = o + r * nx;
    bool any_seed = false, any_positive = false;
    for (int x = 0; x < nx; ++x) {
      envelope.line[x] = row[x];
      any_seed |= row[x] <= cap2;
      any_positive |= row[x] > 0;
    }
    if (any_seed && any_positive) envelope.run(nx, cap2, row, 1);
  }
}

}  // namespace downstream_perception
