#include "downstream_perception/core/tsdf/tsdf_integrator.h"

#include <tsl/robin_set.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <utility>

#include "downstream_perception/core/parallel/avx2_clones.h"
#include "downstream_perception/core/tsdf/depth_rims.h"
#include "downstream_perception/core/tsdf/depth_windows.h"

namespace downstream_perception {

std::string PinholeCamera::validate() const {
  std::ostringstream why;
  if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0.0 && fy > 0.0)) {
    why << "focal lengths must be finite and > 0, got fx " << fx << ", fy " << fy;
  } else if (!(std::isfinite(cx) && std::isfinite(cy))) {
    why << "principal point must be finite";
  } else if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    why << "image size must be in [1, 16384] pixels, got " << width << " x " << height;
  } else if (!(cx >= -kMaxPrincipalPointOffset * width &&
               cx <= (1.0 + kMaxPrincipalPointOffset) * width &&
               cy >= -kMaxPrincipalPointOffset * height &&
               cy <= (1.0 + kMaxPrincipalPointOffset) * height)) {
    why << "principal point (" << cx << ", " << cy << ") px lies more than "
        << kMaxPrincipalPointOffset << " image sizes outside the " << width << " x " << height
        << " image";
  } else {
    // The pixel rays farthest off the optical axis: the image's outer pixel edges.
    const double tan_x = std::max(std::abs(-0.5 - cx), std::abs(width - 0.5 - cx)) / fx;
    const double tan_y = std::max(std::abs(-0.5 - cy), std::abs(height - 0.5 - cy)) / fy;
    if (!(tan_x <= kMaxViewTangent && tan_y <= kMaxViewTangent)) {
      why << "view too wide: the image's edge rays are " << std::atan(std::max(tan_x, tan_y))
          << " rad off the optical axis (at most atan(" << kMaxViewTangent
          << ") = 1.47 rad); focal lengths fx " << fx << ", fy " << fy << " px";
    }
  }
  return why.str();
}

// The integration's steps are inlined into DepthIntegrator::integrate, which is built twice
// (baseline and AVX2, below): a step left as a baseline function would run its loops narrow.
#define DP_INTEGRATION_STEP [[gnu::always_inline]] inline

namespace {

/// Creases (classifyDepthWindows): a window bent less than this many voxels from a plane is one.
/// Above float rounding (a plane's windows bend by up to about 5e-7 of their depth: 5 um at 10 m,
/// a quarter of this at 2 cm voxels), far below what a voxel resolves.
constexpr double kCreaseMinVoxels = 1e-2;
/// Under depth noise, creases are also found by their slope change summed over this many lines
/// on each side along them (six in all; classifyDepthWindows): at 5 cm, 320 x 240, 5 mm noise,
/// 2 (and 1 or 4) turned the worst completeness gap to legacy from -0.0117 to -0.0045 (-0.0046,
/// -0.0044).
constexpr int kCreaseSumRadius = 2;

/// Observation weight of a depth z (m) for the configured weighting, with the behind-surface
/// drop-off applied to sdf (m). The settings are read once per frame, not once per voxel.
class ObservationWeight {
 public:
  ObservationWeight(const TsdfConfig& c, float mu)
      : inverse_square_(c.weighting == TsdfConfig::Weighting::kInverseSquareDepth),
        // A start at or beyond mu leaves nothing to ramp (and 1 / (mu - start) would be <= 0).
        dropoff_(c.behind_surface_dropoff &&
                 c.behind_surface_dropoff_start_voxels * c.voxel_size_m < static_cast<double>(mu)),
        start_(static_cast<float>(c.behind_surface_dropoff_start_voxels * c.voxel_size_m)),
        mu_(mu),
        inv_dropoff_span_(dropoff_ ? 1.0f / (mu - start_) : 0.0f) {}
  /// Branch-free (selects only), so a loop calling it vectorises.
  float operator()(float z, float sdf) const {
    const float w = inverse_square_ ? 1.0f / (z * z) : 1.0f;
    const float dropped = w * ((mu_ + sdf) * inv_dropoff_span_);
    // Grazing reach updates deeper than mu, where the ramp would go negative: weight 0 there.
    return dropoff_ & (sdf < -start_) ? std::max(0.0f, dropped) : w;
  }

 private:
  bool inverse_square_;
  bool dropoff_;
  float start_;  ///< m behind the surface where the ramp starts
  float mu_;
  /// 1 / (mu - start); only used with dropoff_, where mu > start.
  float inv_dropoff_span_;
};

DP_INTEGRATION_STEP Eigen::Vector3i blockOfPoint(const Eigen::Vector3d& p, double inv_voxel) {
  // Voxel = round(p / s); block = floor(voxel / 8), computed on doubles.
  const Eigen::Vector3d q = p * inv_voxel + Eigen::Vector3d::Constant(0.5);
  // floor(floor(q) / 8) = floor(q / 8), and dividing by 8 is exact in binary floating point.
  constexpr double kInvSide = 1.0 / kTsdfBlockSide;
  return {static_cast<int>(std::floor(q.x() * kInvSide)),
          static_cast<int>(std::floor(q.y() * kInvSide)),
          static_cast<int>(std::floor(q.z() * kInvSide))};
}

// A depth image checked once per frame: depth (m; NaN invalid, +Inf no return) and inverse
// depth (1/m; 0 where not a finite valid depth), so the per-voxel loop does no validation and no
// division for interpolation. A DepthIntegrator keeps one and reuses it: a frame overwrites every
// element, so frames of one size allocate and zero nothing.
struct DepthFrame {
  std::vector<float> depth;
  /// Padded by w + 1 pixels, so the 2 x 2 pixels from any pixel can be read.
  std::vector<float> inverse;
  /// |(x/z, y/z, 1)| of each pixel's ray; depends on the intrinsics only, so recomputed only
  /// when they change.
  std::vector<float> range_per_depth;
  PinholeCamera camera;  ///< the intrinsics range_per_depth was computed for
  /// kFixedRadius: pixels within edge_guard_rad of a depth discontinuity (markNearEdges): what
  /// lies behind them is not known to be behind a surface.
  std::vector<std::uint8_t> near_edge;
  /// Per pixel, how deep behind its surface (m along the ray) voxels are updated (the edge
  /// guard and the grazing reach); empty when both are off (mu everywhere).
  std::vector<float> allowed;
  SeedDistances rim_distances;  ///< kRimDistance: every pixel's distance to the nearest rim
  /// |cos(incidence)| per pixel (incidenceCosines; -1 unknown), when the rim distance rule or
  /// the grazing reach needs it; empty otherwise.
  std::vector<float> cosine;
  /// Per pixel, how deep behind its surface (m along the ray) an update still confirms a voxel
  /// (TsdfConfig::confirm_depth_voxels over the incidence's cosine; +Inf where the incidence is
  /// unknown); empty when off or without incidences (every update confirms).
  std::vector<float> confirm_depth;
  std::vector<float> column_x;              ///< scratch of incidenceCosines
  IncidenceWindowScratch incidence_window;  ///< scratch of windowIncidenceCosines
  std::vector<std::uint8_t> edge;           ///< scratch: the discontinuities' seeds
  /// The near sides of steps over mu that one side continues (markRims): rims for the far
  /// grazing pixels' second look (grazingPlaneAllowances).
  std::vector<std::uint8_t> soft_edge;
  std::vector<std::uint8_t> rows;  ///< scratch: the seeds dilated along rows
  std::vector<float> seed_depth;   ///< scratch: the seeds' depths, then their window minimum
  std::vector<float> rows_depth;   ///< scratch: the seeds' depths' minimum along rows
  /// How a voxel reads its depth from the 2 x 2 pixels from this one (right, down): classified
  /// once per pixel here instead of once per voxel in the integration loop (empty without
  /// interpolate_depth).
  std::vector<DepthWindow> window_class;
  DepthWindowScratch windows;
  float min_depth = std::numeric_limits<float>::infinity();
};

/// f->confirm_depth from the incidences (f->cosine): TsdfConfig::confirmDepth() behind the
/// surface along the normal is that over the cosine along the ray. Unknown incidences confirm
/// at any depth (the frame cannot tell how deep along the normal its ray is).
void confirmDepths(const TsdfConfig& c, DepthFrame* f) {
  if (!(c.confirm_depth_voxels > 0.0) || f->cosine.empty()) {
    f->confirm_depth.clear();
    return;
  }
  const float along_normal = static_cast<float>(c.confirmDepth());
  const float inf = std::numeric_limits<float>::infinity();
  f->confirm_depth.resize(f->cosine.size());
  for (std::size_t i = 0; i < f->cosine.size(); ++i) {
    const float cosine = f->cosine[i];
    f->confirm_depth[i] = cosine > 0.0f ? along_normal / cosine : inf;
  }
}

void computeRangePerDepth(const PinholeCamera& camera, DepthFrame* f) {
  const std::size_t n = static_cast<std::size_t>(camera.width) * camera.height;
  if (f->range_per_depth.size() == n && f->camera.fx == camera.fx && f->camera.fy == camera.fy &&
      f->camera.cx == camera.cx && f->camera.cy == camera.cy && f->camera.width == camera.width) {
    return;
  }
  f->range_per_depth.resize(n);
  for (int v = 0; v < camera.height; ++v) {
    const double y = (v - camera.cy) / camera.fy;
    for (int u = 0; u < camera.width; ++u) {
      const double x = (u - camera.cx) / camera.fx;
      f->range_per_depth[static_cast<std::size_t>(v) * camera.width + u] =
          static_cast<float>(std::sqrt(1.0 + x * x + y * y));
    }
  }
  f->camera = camera;
}

/// Which neighbours of a pixel pair (i, j = i + step) along an image line are in the image:
/// a = i - step, b = j + step, a2 = i - 2 step, c = j + 2 step.
struct PairNeighbours {
  bool a, b, a2, c;
};

/// continuesSurface's occluding-edge test, for a near pixel (depth d_near) whose side's plane
/// predicts the inverse depth p_far for the farther pixel (depth d_far) across the step: the
/// farther pixel lies beyond that continuation, and the plane of its own side (its next two
/// pixels' inverse depths inv_f1, inv_f2; 0: invalid or outside the image) predicts it better.
DP_INTEGRATION_STEP bool endsBetweenRays(float d_near, float d_far, float p_far, float inv_f1,
                                         float inv_f2) {
  const bool ended = (d_near < d_far) & (d_far * p_far > 1.0f);
  const float q = 2.0f * inv_f1 - inv_f2;
  const bool far_plane = (inv_f1 != 0.0f) & (inv_f2 != 0.0f) & (q > 0.0f) &
                         (std::abs(d_far * q - 1.0f) < std::abs(d_far * p_far - 1.0f));
  return ended & far_plane;
}

/// Whether a step of more than the jump between neighbouring pixels i and j = i + step (both
/// valid) continues one surface. On a plane inverse depth is affine along an image line, so
/// from a = i - step, 2 / d_i - 1 / d_a predicts 1 / d_j (from_i), and from b = j + step,
/// 2 / d_j - 1 / d_b predicts 1 / d_i (from_j); a zero inverse depth (invalid, or outside the
/// image) predicts nothing. One prediction within `tol` (m) is a surface seen at grazing
/// incidence, which steps by more than the jump per pixel far away, unless the step is an
/// occluding edge after all: the side that continues is the nearer one, the farther pixel lies
/// beyond its prediction (that surface, continued, would have met the farther pixel's ray
/// first: it ends between the two rays), and the farther pixel's own side (it and its next two
/// pixels) forms a plane that predicts it better than the continuation does. A board a few
/// centimetres in front of a wall, seen at grazing incidence, steps by more than the gap per
/// pixel, so the wall's pixels continue the board's plane within tol; without this test its far
/// edge was no rim and the board's truncation band ran on into the gap behind it (issue 22:
/// ghosts 0.09 % of the furnished room's mesh at 640x480). A concave corner (a wall seen at
/// grazing meeting the wall across) keeps its reach: the wall across lies before the grazing
/// wall's continuation, and the grazing wall's last pixel, at the corner, is predicted by both
/// planes but exactly only by its own.
DP_INTEGRATION_STEP bool continuesSurface(const float* inv, const float* dep, std::size_t i,
                                          std::size_t step, const PairNeighbours& has, float tol,
                                          bool* one_side) {
  const std::size_t j = i + step;
  const float inv_a = has.a ? inv[i - step] : 0.0f;
  const float inv_b = has.b ? inv[j + step] : 0.0f;
  const float d_i = dep[i], d_j = dep[j];
  const float p_j = 2.0f * inv[i] - inv_a;
  const float p_i = 2.0f * inv[j] - inv_b;
  const bool from_i = (inv_a != 0.0f) & predictsDepth(p_j, d_j, tol);
  const bool from_j = (inv_b != 0.0f) & predictsDepth(p_i, d_i, tol);
  *one_side = from_i != from_j;
  if (from_i == from_j) return from_i;
  // One side continues: the near side (a, i) when from_i, with j the farther pixel and (b, c)
  // its own side; else the near side is (b, j), i the farther pixel and (a, a2) its side.
  if (from_i) return !endsBetweenRays(d_i, d_j, p_j, inv_b, has.c ? inv[j + 2 * step] : 0.0f);
  return !endsBetweenRays(d_j, d_i, p_i, inv_a, has.a2 ? inv[i - 2 * step] : 0.0f);
}

/// Dilates `edge` (w x h bytes) by `radius` pixels (a separable box) into f->near_edge: each
/// output is the OR of its window, the first term assigned (so the buffers need no clearing).
DP_INTEGRATION_STEP void dilateEdges(int w, int h, int radius, DepthFrame* f) {
  const std::uint8_t* edge = f->edge.data();
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* src = edge + static_cast<std::size_t>(v) * w;
    std::uint8_t* dst = f->rows.data() + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) dst[u] = src[u];
    for (int k = 1; k <= radius && k < w; ++k) {
      for (int u = 0; u + k < w; ++u) dst[u] |= src[u + k];
      for (int u = k; u < w; ++u) dst[u] |= src[u - k];
    }
  }
  const std::uint8_t* rows = f->rows.data();
  std::uint8_t* out = f->near_edge.data();
  for (int v = 0; v < h; ++v) {
    std::uint8_t* dst = out + static_cast<std::size_t>(v) * w;
    const int v0 = std::max(0, v - radius), v1 = std::min(h - 1, v + radius);
    const std::uint8_t* first = rows + static_cast<std::size_t>(v0) * w;
    for (int u = 0; u < w; ++u) dst[u] = first[u];
    for (int k = v0 + 1; k <= v1; ++k) {
      const std::uint8_t* src = rows + static_cast<std::size_t>(k) * w;
      for (int u = 0; u < w; ++u) dst[u] |= src[u];
    }
  }
}

/// Spreads the edge seeds by `radius` pixels into f->near_edge, but only to pixels at most
/// `jump` (m) farther than the nearest seed in their window (a separable minimum filter of the
/// seeds' depths): the object beside its rim, not the background beside the object.
DP_INTEGRATION_STEP void spreadOverNearSide(int w, int h, float jump, int radius, DepthFrame* f) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const float inf = std::numeric_limits<float>::infinity();
  const std::uint8_t* edge = f->edge.data();
  const float* dep = f->depth.data();
  f->seed_depth.resize(n);
  f->rows_depth.resize(n);
  float* seed = f->seed_depth.data();
  for (std::size_t i = 0; i < n; ++i) seed[i] = edge[i] ? dep[i] : inf;
  for (int v = 0; v < h; ++v) {
    const float* src = seed + static_cast<std::size_t>(v) * w;
    float* dst = f->rows_depth.data() + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) dst[u] = src[u];
    for (int k = 1; k <= radius && k < w; ++k) {
      for (int u = 0; u + k < w; ++u) dst[u] = std::min(dst[u], src[u + k]);
      for (int u = k; u < w; ++u) dst[u] = std::min(dst[u], src[u - k]);
    }
  }
  // Column pass into seed (no longer needed as seeds), then the test against the depth.
  const float* rows = f->rows_depth.data();
  for (int v = 0; v < h; ++v) {
    float* dst = seed + static_cast<std::size_t>(v) * w;
    const int v0 = std::max(0, v - radius), v1 = std::min(h - 1, v + radius);
    const float* first = rows + static_cast<std::size_t>(v0) * w;
    for (int u = 0; u < w; ++u) dst[u] = first[u];
    for (int k = v0 + 1; k <= v1; ++k) {
      const float* src = rows + static_cast<std::size_t>(k) * w;
      for (int u = 0; u < w; ++u) dst[u] = std::min(dst[u], src[u]);
    }
  }
  std::uint8_t* out = f->near_edge.data();
  // NaN depths (invalid) fail the compare; +Inf ones too (an infinite seed is no seed).
  for (std::size_t i = 0; i < n; ++i) out[i] = (seed[i] != inf) & (dep[i] <= seed[i] + jump);
}

/// The rims (seeds) of the edge guard, into f->edge. Two neighbouring pixels (along a row or a
/// column) are a depth discontinuity when one is not a valid depth (NaN, +Inf) or their depths
/// differ by more than `jump` (m) and the step does not continuesSurface within jump / 2 (a
/// surface seen at a grazing angle far away steps by more than mu from pixel to pixel, but
/// continues its neighbours' plane: no rim there). near_side_only: the nearer pixel of a
/// discontinuity (the valid one next to an invalid one) is a seed; else both valid pixels are.
/// soft (w x h, zeroed by the caller), if given: the nearer pixel of each step that only one
/// side continues (the second look's extra rims, grazingPlaneAllowances).
DP_INTEGRATION_STEP void markRims(int w, int h, float jump, bool near_side_only, DepthFrame* f,
                                  std::uint8_t* soft = nullptr) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  f->edge.assign(n, 0);
  const float* inv = f->inverse.data();
  const float* dep = f->depth.data();
  std::uint8_t* edge = f->edge.data();
  const float tol = 0.5f * jump;
  // The pair (i, i + step); `has`: which of its outer neighbours are in the image.
  const auto pair = [&](std::size_t i, std::size_t step, const PairNeighbours& has) {
    const std::size_t j = i + step;
    const float di = dep[i], dj = dep[j];
    const bool vi = inv[i] != 0.0f, vj = inv[j] != 0.0f;
    if (std::abs(dj - di) <= jump) return;  // false for NaN and +Inf: they differ
    bool one_side = false;
    if (vi & vj && continuesSurface(inv, dep, i, step, has, tol, &one_side)) {
      if (soft != nullptr && one_side) {  // the nearer side, in case its surface ends there
        soft[i] |= dj > di;
        soft[j] |= di > dj;
      }
      return;
    }
    if (near_side_only) {
      edge[i] |= vi & (!vj | (dj > di));
      edge[j] |= vj & (!vi | (di > dj));
    } else {
      edge[i] |= vi;
      edge[j] |= vj;
    }
  };
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u + 1 < w; ++u) {
      pair(static_cast<std::size_t>(v) * w + u, 1, {u > 0, u + 2 < w, u > 1, u + 3 < w});
    }
  }
  for (int v = 0; v + 1 < h; ++v) {
    for (int u = 0; u < w; ++u) {
      pair(static_cast<std::size_t>(v) * w + u, static_cast<std::size_t>(w),
           {v > 0, v + 2 < h, v > 1, v + 3 < h});
    }
  }
}

/// kFixedRadius: the guard's mask f->near_edge. The rims (markRims) spread by `radius` pixels:
/// near_side_only, only over pixels not more than `jump` farther (spreadOverNearSide); else to
/// every pixel within `radius` (the guard before issue 22's defect 4).
DP_INTEGRATION_STEP void markNearEdges(int w, int h, float jump, int radius, bool near_side_only,
                                       DepthFrame* f) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  markRims(w, h, jump, near_side_only, f);
  f->rows.resize(n);
  f->near_edge.resize(n);
  if (near_side_only) {
    spreadOverNearSide(w, h, jump, radius, f);
  } else {
    dilateEdges(w, h, radius, f);
  }
}

/// kFixedRadius (or no guard): how deep behind its surface (m along the ray) each pixel updates
/// voxels, into f->allowed. A guarded pixel (f->near_edge): a voxel divided by the cosine of the
/// incidence angle (incidenceCosine), at most `max_voxels` voxels and mu; a voxel at the rim
/// pixels themselves (the seeds in f->edge) and where the incidence is unknown. At grazing
/// incidence a voxel just under the surface lies several voxels behind it along the ray; without
/// this the faces seen edge-on next to an object's rim (a box top seen from a little above it) got
/// no "inside" values at all and no surface. Other pixels: the grazing reach (mu without it; with
/// it f->cosine holds every pixel's incidence).
DP_INTEGRATION_STEP void guardDepths(const PinholeCamera& cam, const RimAllowanceSettings& rs,
                                     float max_voxels, DepthFrame* f) {
  const int w = cam.width, h = cam.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  f->allowed.assign(n, rs.truncation);
  const bool guard = !f->near_edge.empty();
  const float min_cos = 1.0f / max_voxels;
  const float* dep = f->depth.data();
  const float* inv = f->inverse.data();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (inv[i] == 0.0f) continue;
      if (guard && f->near_edge[i]) {
        // The rim itself (a seed): its ray is the one that leaves the object again.
        if (f->edge[i] || !(max_voxels > 1.0f)) {
          f->allowed[i] = rs.voxel;
          continue;
        }
        const float cosine =
            f->cosine.empty() ? incidenceCosine(cam, dep, inv, u, v, rs.jump) : f->cosine[i];
        f->allowed[i] = cosine < 0.0f
                            ? rs.voxel
                            : std::min(rs.truncation, rs.voxel / std::max(cosine, min_cos));
      } else if (!f->cosine.empty()) {
        f->allowed[i] = grazingReach(f->cosine[i], rs);
      }
    }
  }
}

/// The far grazing pixels' second look, after rimAllowances. A surface seen at grazing
/// incidence far away steps by more than mu per pixel, so its pixels get no incidence (no
/// neighbour within mu) and reach only mu along the ray: a board's top seen a few degrees from
/// its plane got no "inside" values a voxel under it (issue 22, defect 4). Where a pixel and its
/// neighbours along a row or column lie on one plane, that plane gives the incidence and with it
/// the grazing reach. But the step from such a board to the wall behind it continues the
/// board's plane too (the wall across a concave corner reads the same), so for this look the
/// near sides of steps one side continues (f->soft_edge) are rims as well, every rim binds
/// (also one nearer by more than mu: on a surface seen this grazing the next pixel lies farther
/// than that), and the rim distance rule bounds the reach. Taken only where it allows more than
/// the first look, so no pixel reaches less deep. Few pixels need it (tens to hundreds per
/// frame), so each is done alone: the incidence by incidenceCosine, the nearest rim by a search
/// of the window beyond which no rim can bind (the travel there exceeds the reach).
DP_INTEGRATION_STEP void grazingPlaneAllowances(const PinholeCamera& camera, float mu,
                                                const RimAllowanceSettings& rs, float metres_per_px,
                                                DepthFrame* f) {
  constexpr int kMaxWindowRadius = 16;  // px; a pixel whose rims could bind farther keeps mu
  const int w = camera.width, h = camera.height;
  const float* dep = f->depth.data();
  const float* inv = f->inverse.data();
  const float* first = f->cosine.data();
  const std::uint8_t* edge = f->edge.data();
  const std::uint8_t* soft = f->soft_edge.data();
  float* allowed = f->allowed.data();
  const float plane_tol = 0.5f * mu;
  RimAllowanceSettings any_rim = rs;
  any_rim.jump = std::numeric_limits<float>::infinity();
  const float scale = rs.rim_scale * metres_per_px;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (!(first[i] < 0.0f) || inv[i] == 0.0f) continue;
      const float c = incidenceCosine(camera, dep, inv, u, v, mu, plane_tol);
      if (!(c > 0.0f)) continue;
      const float z = dep[i];
      const float sine = std::sqrt(std::max(0.0f, 1.0f - c * c));
      // No rim farther than this binds: the travel there is at least the reach.
      const float bind_px = grazingReach(c, rs) * c * sine / (scale * z);
      if (!(bind_px < kMaxWindowRadius)) continue;
      const int r = static_cast<int>(std::ceil(bind_px));
      float best = SeedDistances::kNoSeed;
      std::size_t nearest = i;
      for (int vv = std::max(0, v - r); vv <= std::min(h - 1, v + r); ++vv) {
        for (int uu = std::max(0, u - r); uu <= std::min(w - 1, u + r); ++uu) {
          const std::size_t q = static_cast<std::size_t>(vv) * w + uu;
          const float squared = static_cast<float>((uu - u) * (uu - u) + (vv - v) * (vv - v));
          if ((edge[q] | soft[q]) && squared < best) {
            best = squared;
            nearest = q;
          }
        }
      }
      float rim_c = first[nearest];
      if (nearest != i && rim_c < 0.0f) {
        rim_c = incidenceCosine(camera, dep, inv, static_cast<int>(nearest % w),
                                static_cast<int>(nearest / w), mu, plane_tol);
      }
      const float a = rimAllowance(best, z, c, dep[nearest], rim_c, (edge[i] | soft[i]) != 0, true,
                                   scale, any_rim);
      allowed[i] = std::max(allowed[i], a);
    }
  }
}

/// The frame's depths checked and its per-pixel tables filled (reusing f's buffers).
DP_INTEGRATION_STEP void prepare(const float* depth, const PinholeCamera& camera,
                                 const TsdfConfig& c, TsdfIntegrationStats* stats,
                                 DepthFrame* frame) {
  DepthFrame& f = *frame;
  const int w = camera.width, h = camera.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  computeRangePerDepth(camera, &f);
  f.depth.resize(n);
  f.inverse.resize(n + w + 1);
  // Branch-free classification (vectorised): NaN, 0, negatives and out-of-range depths fail
  // both compares.
  const float min_d = static_cast<float>(c.min_depth_m), max_d = static_cast<float>(c.max_depth_m);
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Raw pointers: the byte stores below may alias anything, so through the vectors the
  // compiler would reload their data pointers at every pixel.
  float* out_depth = f.depth.data();
  float* out_inverse = f.inverse.data();
  std::uint32_t valid_count = 0, no_return_count = 0;  // 32-bit: same lane width as the floats
  // The nearest valid depth, as the bits of a positive float (which order like the floats):
  // an integer minimum vectorises, a float one would need -ffinite-math-only.
  std::int32_t min_bits = 0x7f800000;  // +Inf
  for (std::size_t i = 0; i < n; ++i) {
    const float d = depth[i];
    const bool valid = (d >= min_d) & (d <= max_d);
    const bool no_return = d == inf;
    valid_count += valid;
    no_return_count += no_return;
    out_depth[i] = valid | no_return ? d : nan;
    const float inverse = 1.0f / d;  // unconditional, so the loop has no branch
    out_inverse[i] = valid ? inverse : 0.0f;
    std::int32_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    min_bits = std::min(min_bits, valid ? bits : 0x7f800000);
  }
  std::memcpy(&f.min_depth, &min_bits, sizeof min_bits);
  stats->pixels_valid += valid_count;
  stats->pixels_no_return += no_return_count;
  stats->pixels_invalid += n - valid_count - no_return_count;
  // Carving: +Inf pixels free their rays only in a frame with enough returns (the evidence the
  // sensor sees); otherwise they become invalid (NaN) for the whole integration. NaN and +Inf
  // are alike for the edge and interpolation masks below, so only the no-return updates change.
  if (c.carve_free_space && no_return_count > 0 &&
      valid_count < c.no_return_carve_min_valid_fraction * static_cast<double>(n)) {
    for (std::size_t i = 0; i < n; ++i) {
      out_depth[i] = out_depth[i] == inf ? nan : out_depth[i];
    }
    stats->pixels_no_return_ignored += no_return_count;
  }
  if (c.interpolate_depth) {
    f.window_class.resize(n);
    DepthWindowSettings ws;
    ws.max_step = static_cast<float>(c.voxel_size_m);
    ws.crease_min = static_cast<float>(kCreaseMinVoxels * c.voxel_size_m);
    ws.crease_sum_radius = kCreaseSumRadius;
    classifyDepthWindows(out_depth, out_inverse, w, h, ws, &f.windows, f.window_class.data());
  } else {
    f.window_class.clear();
  }
  const int radius =
      static_cast<int>(std::ceil(c.edge_guard_rad * std::max(camera.fx, camera.fy) - 1e-9));
  const float mu = static_cast<float>(c.truncation());
  RimAllowanceSettings rs;
  rs.voxel = static_cast<float>(c.voxel_size_m);
  rs.truncation = mu;
  rs.jump = mu;
  rs.reach = static_cast<float>(c.grazing_reach_voxels * c.voxel_size_m);
  rs.reach_max = std::max(mu, static_cast<float>(c.grazing_reach_max_voxels * c.voxel_size_m));
  rs.rim_scale = static_cast<float>(c.edge_guard_rim_scale);
  rs.fallback_radius_px = static_cast<float>(radius);
  rs.radians_per_px = static_cast<float>(1.0 / std::min(camera.fx, camera.fy));
  f.near_edge.clear();
  const bool rim_rule = radius > 0 && c.edge_guard_rule == TsdfConfig::EdgeGuardRule::kRimDistance;
  if (rim_rule || rs.reach > 0.0f) {
    f.cosine.resize(n);
    incidenceCosines(camera, f.depth.data(), f.inverse.data(), mu, &f.column_x, f.cosine.data());
    // Window pairs continue a surface within two voxels (at most mu): a face seen at grazing
    // incidence steps by more per pixel, and its windows would reach across the crease into
    // the face beside it.
    const float window_jump = std::min(mu, static_cast<float>(2.0 * c.voxel_size_m));
    windowIncidenceCosines(camera, f.depth.data(), f.inverse.data(), window_jump,
                           c.incidence_window_radius_px, &f.incidence_window, f.cosine.data());
  } else {
    f.cosine.clear();
  }
  if (rim_rule) {
    const bool second_look = rs.reach > 0.0f;
    if (second_look) f.soft_edge.assign(n, 0);
    markRims(w, h, mu, c.edge_guard_near_side_only, &f, second_look ? f.soft_edge.data() : nullptr);
    // Beyond this distance from its rim no pixel is bound by it, so the transform need not look
    // farther: bound means D z / (f c s) < reach(c) = min(reach_max, max(mu, r / c)), so
    // D < f s max(mu c, r) / z <= f max(mu / 2, r) / z (c s = sin(2 theta) / 2 <= 1/2, s <= 1),
    // largest at the frame's nearest depth (D: px from the rim; c, s: cos and sin of the
    // incidence; r: the grazing reach; rim_scale divides; the silhouette factor, >= 1, only
    // lengthens the travel).
    const double focal = std::max(camera.fx, camera.fy);
    const double bound = std::max(0.5 * static_cast<double>(mu), static_cast<double>(rs.reach));
    const double beyond = bound * focal / (c.edge_guard_rim_scale * f.min_depth) + 1.0;
    const float beyond_px = static_cast<float>(std::max(beyond, rs.fallback_radius_px + 1.0));
    seedDistances(w, h, f.edge.data(), &f.rim_distances, beyond_px,
                  {f.depth.data(), f.cosine.data()});
    f.allowed.resize(n);
    const float metres_per_px = static_cast<float>(1.0 / focal);
    rimAllowances(f.depth.data(), f.inverse.data(), f.edge.data(), &f.rim_distances,
                  f.cosine.data(), n, metres_per_px, rs, f.allowed.data());
    if (second_look) grazingPlaneAllowances(camera, mu, rs, metres_per_px, &f);
  } else if (radius > 0 || rs.reach > 0.0f) {
    if (radius > 0) markNearEdges(w, h, mu, radius, c.edge_guard_near_side_only, &f);
    guardDepths(camera, rs, static_cast<float>(c.edge_guard_grazing_voxels), &f);
  } else {
    f.allowed.clear();
  }
  confirmDepths(c, &f);
}

/// Blocks the truncation band of the valid pixels passes through, from mu in front of the
/// surface to the pixel's allowance behind it (DepthFrame::allowed; mu without one; with
/// carve_free_space from the sensor, and the rays of +Inf pixels up to max_depth_m). Pixels are
/// sampled every `stride` pixels, where a stride spans at most one voxel at the nearest depth of
/// the frame (so no surface patch a voxel wide is skipped); neighbouring samples mostly land in the
/// same block, so a one-entry cache per sample along the ray skips most hash lookups. The
/// blocks are listed in the order the image's rows first reach them, so consecutive blocks read
/// nearby pixels (hash order would scatter the integration's pixel reads over the whole image).
/// The list stops at max_blocks keys (`truncated`): the map can hold no more.
DP_INTEGRATION_STEP std::vector<Eigen::Vector3i> bandBlocks(const DepthFrame& f,
                                                            const PinholeCamera& camera,
                                                            const Eigen::Isometry3d& T,
                                                            const TsdfConfig& c, bool* truncated) {
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> seen;
  std::vector<Eigen::Vector3i> keys;
  // Without a valid depth only carving (along +Inf rays) has anything to do.
  if (!std::isfinite(f.min_depth) && !c.carve_free_space) return keys;
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const double block_m = kTsdfBlockSide * s;
  const double focal = std::min(camera.fx, camera.fy);
  // Sampled rays at most a voxel apart at the nearest depth; carving also needs them at most
  // half a block apart at max_depth_m, the farthest it carves.
  double spacing_px = std::isfinite(f.min_depth) ? 0.5 * s * focal / f.min_depth : 1e9;
  if (c.carve_free_space) spacing_px = std::min(spacing_px, 0.5 * block_m * focal / c.max_depth_m);
  const int stride = std::max(1, static_cast<int>(std::floor(spacing_px)));
  // Samples along each ray at most half a block apart.
  const auto samplesFor = [&](double length) {
    return std::max(2, static_cast<int>(std::ceil(length / (0.5 * block_m))) + 1);
  };
  const bool carve = c.carve_free_space;
  const int samples = carve ? samplesFor(c.max_depth_m + mu) : samplesFor(2.0 * mu);
  const bool has_allowed = !f.allowed.empty();
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  const int w = camera.width, h = camera.height;
  // One cache per sample along the ray: neighbouring pixels' k-th samples share blocks.
  std::vector<Eigen::Vector3i> last(samples,
                                    Eigen::Vector3i(std::numeric_limits<int>::min(), 0, 0));
  const auto next = [stride](int a, int size) {
    // Every stride-th pixel and always the last one.
    return a + stride < size || a == size - 1 ? a + stride : size - 1;
  };
  for (int v = 0; v < h; v = next(v, h)) {
    for (int u = 0; u < w; u = next(u, w)) {
      const std::size_t pixel = static_cast<std::size_t>(v) * w + u;
      float d = f.depth[pixel];
      if (carve && d == std::numeric_limits<float>::infinity()) {
        d = static_cast<float>(c.max_depth_m - mu);  // no return: free up to max_depth_m
      }
      if (!std::isfinite(d)) continue;
      const Eigen::Vector3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      const double norm = ray.norm();
      const double range = d * norm;
      const Eigen::Vector3d dir = R * (ray / norm);
      const double r0 = carve ? 0.0 : std::max(0.0, range - mu);
      // +Inf pixels have the allowance mu (no valid depth).
      const double end = range + (has_allowed ? f.allowed[pixel] : mu);
      const int n = samplesFor(end - r0);
      if (n > static_cast<int>(last.size())) {
        last.resize(n, Eigen::Vector3i(std::numeric_limits<int>::min(), 0, 0));
      }
      const double step = (end - r0) / (n - 1);
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3i key = blockOfPoint(t + dir * (r0 + step * k), 1.0 / s);
        if (key == last[k]) continue;
        last[k] = key;
        if (!seen.insert(key).second) continue;
        keys.push_back(key);
        if (keys.size() >= c.max_blocks) {
          *truncated = true;
          return keys;
        }
      }
    }
  }
  return keys;
}

void evict(TsdfMap* map, const Eigen::Vector3d& origin, TsdfIntegrationStats* stats) {
  map->setSensorOrigin(origin);
  const double limit = map->config().max_block_distance_m;
  if (limit > 0.0) stats->blocks_evicted = map->evictFartherThan(origin, limit);
}

/// Why a depth frame cannot be integrated at all, or nullptr: invalid intrinsics, or a pose
/// whose rays (up to max_depth_m, at most atan(kMaxViewTangent) off the axis) could leave the
/// map's index range (TsdfMap::inBounds), or is not finite.
const char* refusedFrame(const TsdfMap& map, const PinholeCamera& camera,
                         const Eigen::Isometry3d& T_map_camera) {
  if (!camera.validate().empty()) return "invalid camera intrinsics";
  const TsdfConfig& c = map.config();
  const double reach =
      std::sqrt(1.0 + 2.0 * kMaxViewTangent * kMaxViewTangent) * (c.max_depth_m + c.truncation()) +
      2.0 * kTsdfBlockSide * c.voxel_size_m;
  if (!T_map_camera.matrix().allFinite() ||
      !map.inBounds(T_map_camera.translation().cwiseAbs() + Eigen::Vector3d::Constant(reach))) {
    return "camera pose not finite or beyond the map's index range";
  }
  return nullptr;
}

}  // namespace

struct DepthIntegrator::Buffers : DepthFrame {};

DepthIntegrator::DepthIntegrator() : buffers_(std::make_unique<Buffers>()) {}
DepthIntegrator::~DepthIntegrator() = default;
DepthIntegrator::DepthIntegrator(DepthIntegrator&&) noexcept = default;
DepthIntegrator& DepthIntegrator::operator=(DepthIntegrator&&) noexcept = default;

// The per-pixel and per-voxel loops vectorise twice as wide with AVX2 (avx2_clones.h): both
// copies give bit-identical maps.
DP_AVX2_CLONES
TsdfIntegrationStats DepthIntegrator::integrate(TsdfMap* map, const float* depth,
                                                const PinholeCamera& camera,
                                                const Eigen::Isometry3d& T_map_camera) {
  DepthFrame* scratch = buffers_.get();
  TsdfIntegrationStats stats;
  const TsdfConfig& c = map->config();
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const int w = camera.width;
  const int h = camera.height;
  stats.refused = refusedFrame(*map, camera, T_map_camera);
  if (stats.refused != nullptr) {
    const bool sized = w > 0 && h > 0 && w <= 16384 && h <= 16384;
    stats.pixels_invalid = sized ? static_cast<std::size_t>(w) * h : 0;
    return stats;
  }
  const std::uint64_t generation = map->beginIntegration();
  prepare(depth, camera, c, &stats, scratch);
  const DepthFrame& frame = *scratch;
  bool truncated = false;
  const auto keys = bandBlocks(frame, camera, T_map_camera, c, &truncated);
  stats.blocks_refused += truncated;

  // Every voxel of those blocks, a row of eight at a time, in three passes: project (vectorised),
  // load the pixel data each voxel needs (scalar loads), fuse (vectorised and branch-free, so
  // its two divisions run eight voxels at once and no data-dependent branch mispredicts).
  const float max_step = static_cast<float>(s);
  const Eigen::Isometry3d T_camera_map = T_map_camera.inverse();
  // The voxel loop runs in float (voxel positions relative to the camera, within max_depth_m:
  // float resolves them to well under a micrometre per metre).
  const Eigen::Matrix3f Rc = T_camera_map.linear().cast<float>();
  const Eigen::Vector3f dx = Rc.col(0) * static_cast<float>(s);
  const Eigen::Vector3f dy = Rc.col(1) * static_cast<float>(s);
  const Eigen::Vector3f dz = Rc.col(2) * static_cast<float>(s);
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx) + 0.5f, cy = static_cast<float>(camera.cy) + 0.5f;
  const float min_z = static_cast<float>(c.min_depth_m), max_z = static_cast<float>(c.max_depth_m);
  const float muf = static_cast<float>(mu);
  const float u_end = static_cast<float>(w), v_end = static_cast<float>(h);
  const bool interpolate = c.interpolate_depth;
  const ObservationWeight weight(c, muf);
  const float inv_mu = 1.0f / muf;
  // Per-pixel allowances behind the surface (edge guard, grazing reach), or mu everywhere.
  const bool has_allowed = !frame.allowed.empty();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float* depth_px = frame.depth.data();
  const float* range_px = frame.range_per_depth.data();
  const float* inverse_px = frame.inverse.data();
  const DepthWindow* window_class_px = frame.window_class.data();
  // Pass 2's per-voxel pixel data. A row writes the nearest depth of all eight voxels and the
  // rest only for voxels in the band; the others keep an earlier row's finite values, which
  // pass 3's selects discard.
  alignas(32) float nearest[kTsdfBlockSide] = {}, range[kTsdfBlockSide] = {};
  alignas(32) float i00[kTsdfBlockSide] = {}, i10[kTsdfBlockSide] = {}, i01[kTsdfBlockSide] = {},
                    i11[kTsdfBlockSide] = {};
  alignas(32) int flags[kTsdfBlockSide] = {};      // 0: nearest pixel, 1: interpolate, 2: crease
  alignas(32) float creased[kTsdfBlockSide] = {};  // depth across a crease (creaseInverseDepth)
  alignas(32) float allowed[kTsdfBlockSide] = {};
  const float* allowed_px = frame.allowed.data();
  alignas(32) float confirm_depth[kTsdfBlockSide] = {};
  const bool has_confirm_depth = !frame.confirm_depth.empty();
  const float* confirm_depth_px = frame.confirm_depth.data();
  // A non-confirming update's weight factor (TsdfConfig::unconfirmed_update_weight).
  const float unconfirmed_weight = static_cast<float>(map->config().unconfirmed_update_weight);
  // TsdfConfig::far_free_guess_weight: a guess's factor on a voxel seen far free, and a far-free
  // update's on an unconfirmed voxel.
  const float far_free_guess = static_cast<float>(map->config().far_free_guess_weight);
  const float far_free_boost = 1.0f / far_free_guess;
  // The blocks are found (or allocated) first, so each block's integration can prefetch the
  // next block's voxels: blocks lie scattered in memory, where the hardware prefetcher does not
  // follow.
  std::vector<TsdfBlock*> blocks(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    bool created = false;
    blocks[i] = map->allocate(keys[i], &created);
    stats.blocks_allocated += created;
    stats.blocks_refused += blocks[i] == nullptr;
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const Eigen::Vector3i& key = keys[i];
    TsdfBlock* block = blocks[i];
    if (block == nullptr) continue;
    const TsdfBlock* next = i + 1 < keys.size() ? blocks[i + 1] : nullptr;
    ++stats.blocks_touched;
    bool touched = false;
    const Eigen::Vector3f base =
        (T_camera_map * ((key * kTsdfBlockSide).cast<double>() * s)).cast<float>();
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        const Eigen::Vector3f row = base + dz * static_cast<float>(z) + dy * static_cast<float>(y);
        if (next != nullptr) __builtin_prefetch(&next->voxels[TsdfBlock::linear(0, y, z)], 1);
        // Pass 1, the row's eight projections at once (plain loops the compiler vectorises):
        // depth along the axis, NaN when the voxel is too close or outside the image (so no
        // test below passes); the nearest pixel (coordinates shifted by half a pixel, so
        // truncation rounds to the nearest pixel centre: no half-pixel bias); the 2 x 2 pixels
        // around it for interpolation.
        alignas(32) float zc[kTsdfBlockSide], frac_u[kTsdfBlockSide], frac_v[kTsdfBlockSide];
        alignas(32) int pixel[kTsdfBlockSide], cell[kTsdfBlockSide], corners_ok[kTsdfBlockSide];
        int in_view = 0;
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const float fxv = static_cast<float>(x);
          const float px = row.x() + dx.x() * fxv;
          const float py = row.y() + dx.y() * fxv;
          const float pz = row.z() + dx.z() * fxv;
          const float inv_z = 1.0f / pz;
          const float u = fx * px * inv_z + cx;
          const float v = fy * py * inv_z + cy;
          const bool ok = (pz >= min_z) & (u >= 0.0f) & (v >= 0.0f) & (u < u_end) & (v < v_end);
          const float us = ok ? u : 0.0f, vs = ok ? v : 0.0f;
          zc[x] = ok ? pz : nan;  // NaN: never updated
          pixel[x] = ok ? static_cast<int>(vs) * w + static_cast<int>(us) : 0;
          // The 2 x 2 pixel centres around the projection, for interpolation: us - 0.5 >= -0.5,
          // so its integer part is a pixel (the inverse-depth table is padded for the last).
          const float uf = us - 0.5f, vf = vs - 0.5f;
          const int u0 = static_cast<int>(uf), v0 = static_cast<int>(vf);
          frac_u[x] = uf - static_cast<float>(u0);
          frac_v[x] = vf - static_cast<float>(v0);
          cell[x] = v0 * w + u0;
          corners_ok[x] = (uf >= 0.0f) & (vf >= 0.0f);
          in_view |= ok;
        }
        if (!in_view) continue;
        // Pass 2, per voxel: the pixel data it needs, by scalar loads (AVX2's gathers are
        // slower than scalar loads on AMD Zen 2). Interpolation moves the depth by at most
        // max_step, hence the band's margins.
        bool any_update = false;
        unsigned creases = 0;  // bit x: voxel x's pixels are a crease window
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const std::size_t px = static_cast<std::size_t>(pixel[x]);
          nearest[x] = depth_px[px];
          // The pixel's allowance behind its surface, for every voxel (pass 3 reads it for all
          // eight): deeper voxels skip the loads below.
          allowed[x] = has_allowed ? allowed_px[px] : muf;
          confirm_depth[x] =
              has_confirm_depth ? confirm_depth_px[px] : std::numeric_limits<float>::infinity();
          const float along_axis = nearest[x] - zc[x];
          // Behind the band, or NaN (|sdf| >= |along_axis|: the ray is at least as long).
          if (!(along_axis >= -allowed[x] - max_step)) continue;
          any_update = true;
          if (!(along_axis <= muf + max_step)) continue;  // in front: free space
          range[x] = range_px[px];
          int flag = 0;
          if (interpolate) {
            const float* inv = inverse_px + cell[x];
            i00[x] = inv[0];
            i10[x] = inv[1];
            i01[x] = inv[w];
            i11[x] = inv[w + 1];
            flag = corners_ok[x] ? static_cast<int>(window_class_px[cell[x]]) : 0;
            creases |= static_cast<unsigned>(flag >= 2) << x;
          }
          flags[x] = flag;
        }
        if (!any_update) continue;
        // Creases: few voxels, each done alone (a plain scalar path kept out of pass 2's loop).
        for (unsigned bits = creases; bits != 0; bits &= bits - 1) {
          const int x = __builtin_ctz(bits);
          const int u0 = cell[x] % w, v0 = cell[x] / w;
          const CreaseDepth crease =
              creaseInverseDepth(inverse_px, w, h, u0, v0, frac_u[x], frac_v[x],
                                 static_cast<DepthWindow>(flags[x]), max_step);
          float depth = 1.0f / crease.inverse;
          // At a concave crease, at least the farthest of the four pixels: the planes'
          // meeting point leaves the voxels on the corner line within rounding of zero, and
          // marching cubes, reading them a hair negative, still cut the corner off; this
          // errs towards free space by at most the window's depth spread (a voxel) and only
          // next to the crease (5 cm voxels, the room on the lattice: completeness 0.9465
          // with the planes alone, 0.9755 with this; Open3D legacy 0.9587).
          if (crease.concave) {
            depth = std::max(depth,
                             1.0f / std::min(std::min(i00[x], i10[x]), std::min(i01[x], i11[x])));
          }
          // Within the band's margins of the nearest pixel (a crease lies within a voxel
          // of its pixels).
          creased[x] = std::clamp(depth, nearest[x] - max_step, nearest[x] + max_step);
          // None (a neighbour missing): interpolate.
          flags[x] = crease.inverse > 0.0f ? 2 : 1;
        }
        // Pass 3, the row's eight fusions at once (a plain loop the compiler vectorises; a
        // voxel that is not updated keeps its value through the selects).
        TsdfVoxel* row_voxels = &block->voxels[TsdfBlock::linear(0, y, z)];
        // The row's far-free bits unpacked and packed outside the loop, which keeps it plain.
        std::uint8_t& far_free_row =
            block->far_free_rows[TsdfBlock::linear(0, y, z) / kTsdfBlockSide];
        alignas(32) int seen_far_free[kTsdfBlockSide], far_free[kTsdfBlockSide];
        for (int x = 0; x < kTsdfBlockSide; ++x) seen_far_free[x] = (far_free_row >> x) & 1;
        int updated = 0;
        for (int x = 0; x < kTsdfBlockSide; ++x) {
          const float z_axis = zc[x];
          // Invalid pixels (NaN) and voxels clearly behind the band are not updated; +Inf (no
          // return within range) is free space along the whole ray.
          const float along_axis = nearest[x] - z_axis;
          const bool no_return = nearest[x] > max_z;
          const bool in_band = !no_return & (along_axis <= muf + max_step);
          // Inverse depth interpolated bilinearly between the four surrounding pixel centres
          // (exact on planes, where 1/z is affine in the image); across a crease (a window bent
          // beyond the frame's noise) the two planes meeting there (creaseInverseDepth, pass
          // 2); else the nearest pixel's depth (a depth edge or an invalid pixel, the image's
          // first half pixel). Across a concave crease (a room's corner, a box's foot) the
          // interpolation is a chord, nearer than both planes: the voxels on the corner line
          // fused negative and marching cubes cut the corner off a voxel wide, a chamfer (issue
          // 22, defect 4).
          const float a = frac_u[x], b = frac_v[x];
          const float interpolated = 1.0f / ((1.0f - b) * ((1.0f - a) * i00[x] + a * i10[x]) +
                                             b * ((1.0f - a) * i01[x] + a * i11[x]));
          const float d = flags[x] == 1 ? interpolated : flags[x] == 2 ? creased[x] : nearest[x];
          // sdf = (depth - z) * |ray| / z, with |ray| / z from the pixel's table.
          // Where a pixel's reach behind its surface is cut below mu (next to a rim) its band is
          // cut alike in front: a value beyond the allowance counts as the allowance, as values
          // beyond mu count as mu. Cut on one side only, the band kept the front half of a
          // zero-mean spread (pixel steps at grazing incidence, depth noise) and pushed the voxels
          // at the surface positive: a surface on a plane of voxel centres lost its crossings
          // next to its rims (issue 22, defect 4). Elsewhere (allowance >= mu) this changes
          // nothing, and the tests below only look at values behind the surface.
          const float sdf = in_band ? std::min((d - z_axis) * range[x], allowed[x]) : muf;
          const bool update =
              (along_axis >= -allowed[x] - max_step) &
              !(no_return & (z_axis > max_z)) &  // no return: free only up to max_depth_m
              // Not deeper than the pixel's allowance: mu, less next to a rim (the ray may have
              // left the object again), more at grazing incidence (the grazing reach).
              !(in_band & (sdf < -allowed[x]));
          const float dn = std::max(-1.0f, std::min(1.0f, sdf * inv_mu));
          const float obs_w = weight(no_return ? z_axis : nearest[x], sdf);
          TsdfVoxel& voxel = row_voxels[x];
          // Deeper than the confirm depth along the normal: the update fuses, at a lower weight,
          // but does not confirm the voxel (a slab's far side, which no frame may ever see).
          const bool confirms = !(in_band & (sdf < -confirm_depth[x]));
          // Far free: the ray went on more than mu past the voxel (or found no return). A guess
          // on a voxel that reads free and was seen far free counts less, and far free counts
          // more on a voxel only guessed so far: either way round, free space seen beats a guess
          // (TsdfConfig::far_free_guess_weight).
          far_free[x] = update & (sdf >= muf);
          const bool seen_free = (seen_far_free[x] != 0) & (voxel.distance > 0.0f);
          const float boost = (far_free[x] != 0) & (voxel.weight < 0.0f) ? far_free_boost : 1.0f;
          const float factor =
              confirms ? boost : unconfirmed_weight * (seen_free ? far_free_guess : 1.0f);
          const TsdfVoxel fused = map->fused(voxel, dn, obs_w * factor, confirms);
          voxel.distance = update ? fused.distance : voxel.distance;
          voxel.weight = update ? fused.weight : voxel.weight;
          updated += update;
        }
        unsigned far_free_bits = far_free_row;
        for (int x = 0; x < kTsdfBlockSide; ++x)
          far_free_bits |= static_cast<unsigned>(far_free[x]) << x;
        far_free_row = static_cast<std::uint8_t>(far_free_bits);
        stats.voxels_updated += updated;
        touched |= updated != 0;
      }
    }
    if (touched) block->updated_stamp = generation;
  }
  evict(map, T_map_camera.translation(), &stats);
  return stats;
}

TsdfIntegrationStats integrateDepth(TsdfMap* map, const float* depth, const PinholeCamera& camera,
                                    const Eigen::Isometry3d& T_map_camera) {
  return DepthIntegrator().integrate(map, depth, camera, T_map_camera);
}

void millimetresToMetres(const std::uint16_t* millimetres, std::size_t count, float* metres) {
  for (std::size_t i = 0; i < count; ++i) {
    metres[i] = millimetres[i] == 0 ? std::numeric_limits<float>::quiet_NaN()
                                    : 0.001f * static_cast<float>(millimetres[i]);
  }
}

TsdfIntegrationStats integratePoints(TsdfMap* map, const std::vector<Eigen::Vector3d>& points,
                                     const Eigen::Vector3d& origin) {
  TsdfIntegrationStats stats;
  if (!map->inBounds(origin)) {
    stats.refused = "sensor origin not finite or beyond the map's index range";
    stats.pixels_invalid = points.size();
    return stats;
  }
  const TsdfConfig& c = map->config();
  const double s = c.voxel_size_m;
  const double mu = c.truncation();
  const ObservationWeight weight(c, static_cast<float>(mu));
  const std::uint64_t generation = map->beginIntegration();
  tsl::robin_set<Eigen::Vector3i, BlockIndexHash> touched_keys;
  Eigen::Vector3i cached_key(std::numeric_limits<int>::min(), 0, 0);
  TsdfBlock* cached = nullptr;
  for (const Eigen::Vector3d& point : points) {
    if (!map->inBounds(point)) {  // NaN, Inf, or so far that its voxel index could overflow
      ++stats.pixels_invalid;
      continue;
    }
    const Eigen::Vector3d ray = point - origin;
    const double range = ray.norm();
    if (!(range >= c.min_depth_m && range <= c.max_depth_m)) {
      ++stats.pixels_invalid;
      continue;
    }
    ++stats.pixels_valid;
    const Eigen::Vector3d dir = ray / range;
    // Amanatides-Woo traversal of the voxels (cells [i - 1/2, i + 1/2) in voxel units) from
    // range - mu to range + mu.
    const double t0 = c.carve_free_space ? 0.0 : std::max(0.0, range - mu);
    const double t1 = range + mu;
    const Eigen::Vector3d q0 = (origin + dir * t0) / s + Eigen::Vector3d::Constant(0.5);
    Eigen::Vector3i cell(static_cast<int>(std::floor(q0.x())), static_cast<int>(std::floor(q0.y())),
                         static_cast<int>(std::floor(q0.z())));
    Eigen::Vector3i step;
    Eigen::Vector3d t_max, t_delta;
    for (int a = 0; a < 3; ++a) {
      const double da = dir(a) / s;  // voxel units per metre
      if (da > 0.0) {
        step(a) = 1;
        t_delta(a) = 1.0 / da;
        t_max(a) = t0 + (cell(a) + 1 - q0(a)) / da;
      } else if (da < 0.0) {
        step(a) = -1;
        t_delta(a) = -1.0 / da;
        t_max(a) = t0 + (q0(a) - cell(a)) / -da;
      } else {
        step(a) = 0;
        t_delta(a) = t_max(a) = std::numeric_limits<double>::infinity();
      }
    }
    for (double t_cell = t0; t_cell <= t1;) {
      const Eigen::Vector3i key = TsdfMap::blockOf(cell);
      if (key != cached_key) {
        bool created = false;
        cached = map->allocate(key, &created);
        cached_key = key;
        if (cached == nullptr) {
          ++stats.blocks_refused;
        } else {
          stats.blocks_allocated += created;
          touched_keys.insert(key);
          cached->updated_stamp = generation;
        }
      }
      if (cached != nullptr) {
        const double sdf = range - (map->voxelCenter(cell) - origin).dot(dir);
        if (sdf >= -mu) {
          const float dn = static_cast<float>(std::min(1.0, sdf / mu));
          map->fuse(&cached->voxels[TsdfMap::localIndex(cell)], dn,
                    weight(static_cast<float>(range), static_cast<float>(sdf)));
          ++stats.voxels_updated;
        }
      }
      int a = 0;
      if (t_max(1) < t_max(a)) a = 1;
      if (t_max(2) < t_max(a)) a = 2;
      t_cell = t_max(a);
      t_max(a) += t_delta(a);
      cell(a) += step(a);
    }
  }
  stats.blocks_touched = touched_keys.size();
  evict(map, origin, &stats);
  return stats;
}

}  // namespace downstream_perception
