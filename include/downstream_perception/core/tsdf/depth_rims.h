// How deep behind its surface each pixel of a depth image may write "inside" values: the rim
// distance rule of the TSDF integrator (issue 22, defect 4), and the pieces it is made of.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <vector>

#include "downstream_perception/core/tsdf/depth_incidence.h"

namespace downstream_perception {

struct PinholeCamera;

/// Per-pixel squared distance (px^2) to the nearest seed and that seed's index (-1: no seed in
/// the image), from an exact Euclidean distance transform (Felzenszwalb and Huttenlocher's lower
/// envelope of parabolas; the nearest seed in each column first, by sweeping rows, then the
/// envelope along each row: O(pixels), all reads contiguous). Its own because the rule needs
/// the nearest seed itself, which the inflation's and the ESDF's transforms (distances only) do
/// not give. Written by seedDistances; the scratch vectors are reused from call to call.
struct SeedDistances {
  std::vector<float> squared;      ///< px^2; kNoSeed where the image has no seed
  std::vector<std::int32_t> seed;  ///< row-major index of the nearest seed, -1 if none
  /// Per value plane given to seedDistances: that plane's value at the nearest seed (kNoSeed
  /// where there is none).
  std::vector<std::vector<float>> seed_values;
  std::vector<std::int32_t> column_seed_row;  ///< scratch: the nearest seed's row in the column
  std::vector<std::int32_t> column_squared;   ///< scratch: one row's squared column distances
  std::vector<std::int32_t> hull;    ///< scratch: one row's lower envelope (parabola apexes)
  std::vector<std::int64_t> hull_f;  ///< scratch: their heights plus apex^2
  static constexpr float kNoSeed = 1e30f;
};

/// Fills `out` for a w x h image whose seeds are the nonzero bytes of `seeds`. Ties between
/// equally near seeds go to either (both are as near). Exact for every pixel nearer than
/// max_distance_px to a seed; a pixel farther from every seed gets a distance >= it, or kNoSeed
/// and -1 (the search leaves out what cannot come nearer). Infinity: exact everywhere. Each
/// of `planes` (w * h values each) also gives out->seed_values[k] = its value at the nearest
/// seed, written run by run, so callers need no gather.
void seedDistances(int w, int h, const std::uint8_t* seeds, SeedDistances* out,
                   float max_distance_px = std::numeric_limits<float>::infinity(),
                   std::initializer_list<const float*> planes = {});

/// Settings of rimAllowances, all lengths in metres.
struct RimAllowanceSettings {
  float voxel = 0.0f;       ///< voxel size
  float truncation = 0.0f;  ///< mu: the depth every pixel away from rims reaches
  float jump = 0.0f;        ///< a rim's depth step (mu): a pixel farther than its seed by more
                            ///< is the background beside the object, not the object
  /// Grazing reach: every pixel reaches this deep below its surface (along the normal, so
  /// reach / cos(incidence) along the ray), beyond mu if need be; 0 = off (mu along the ray).
  float reach = 0.0f;
  float reach_max = 0.0f;  ///< cap along the ray (>= mu where reach > 0)
  float rim_scale = 1.0f;  ///< scales the depth the rim distance allows
  /// Pixels without an incidence estimate within this many pixels of a seed reach one voxel
  /// (the fixed-radius guard's rule); beyond it mu.
  float fallback_radius_px = 0.0f;
  /// The largest angle between the rays of neighbouring pixels (1 / the smaller focal length,
  /// px): how much a plane's incidence can change from pixel to pixel.
  float radians_per_px = 0.0f;
};

/// A rim whose incidence sine exceeds a pixel's by more than a plane allows (the angle between
/// their rays) plus this is taken as the silhouette of a surface turning towards the line of
/// sight (rimAllowances): the estimate's noise. Why sines and 0.02: at grazing incidence sines
/// differ little, so the far edges of thin boards seen at grazing (whose rims' estimates scatter)
/// are left to the plane rule; compared in cosines with a margin of 0.1, those added ghosts at
/// 640 x 480 (median 0.003 -> 0.017 %). On real PrimeSense frames 0.02 moved the vertices' depth
/// residuals by 0.3 mm at the p95 and double crossings by 0.06 points (issue 22's closing note).
constexpr float kSilhouetteSineMargin = 0.02f;

/// How deep behind its surface (m along the ray) each pixel writes "inside" values, into
/// `allowed` (`pixels` of them; pixels without a valid depth get mu). Rim seeds (the nearer
/// pixel of a depth discontinuity): one voxel. Other pixels: the ray through a pixel D pixels
/// from the nearest rim on its side, entering a surface at incidence theta, travels about
/// D * z * metres_per_px / (cos(theta) * sin(theta)) before it can leave the object through the
/// face behind that rim (z: depth; metres_per_px: 1 / the larger focal length); deeper than that
/// its "inside" is a guess that made ghosts. Where the rim is seen more grazing than the pixel
/// (its incidence's sine larger by more than the angle between their rays, radians_per_px * D,
/// plus kSilhouetteSineMargin; an unknown one counts as grazing), the surface turns towards the
/// line of sight before it ends, as a convex object does at its silhouette: the ray then leaves
/// no earlier than at the silhouette's depth, sin(theta) (1 + sin(theta)) times farther (a
/// sphere's half chord against the plane's travel; at least the plane's). So allowed =
/// min(reach_depth, max(voxel, rim_scale * that)), where reach_depth = grazingReach(cos(theta)).
/// Where the incidence is unknown (cosine < 0): a voxel within fallback_radius_px of a rim, else
/// mu. cosine: from incidenceCosines. distances: from seedDistances, best given the planes
/// {depth, cosine} (their values at the nearest rim); without them they are gathered into it.
void rimAllowances(const float* depth, const float* inverse, const std::uint8_t* seeds,
                   SeedDistances* distances, const float* cosine, std::size_t pixels,
                   float metres_per_px, const RimAllowanceSettings& settings, float* allowed);

/// One pixel of rimAllowances: squared_px its squared distance to the nearest rim
/// (SeedDistances::kNoSeed: none), z its depth, c its incidence cosine (< 0: unknown), rim_z and
/// rim_c the rim's, is_seed whether it is a rim itself, valid whether its depth is;
/// scale = rim_scale * metres_per_px.
[[gnu::always_inline]] inline float rimAllowance(float squared_px, float z, float c, float rim_z,
                                                 float rim_c, bool is_seed, bool valid, float scale,
                                                 const RimAllowanceSettings& s) {
  // The nearest rim counts only if this pixel is on its object (not the background beside
  // it, more than jump farther).
  const bool near_rim = (squared_px < SeedDistances::kNoSeed) & (z <= rim_z + s.jump);
  const float reach = (s.reach > 0.0f) & (c > 0.0f)
                          ? std::min(s.reach_max, std::max(s.truncation, s.reach / c))
                          : s.truncation;
  const float sine = std::sqrt(std::max(0.0f, 1.0f - c * c));
  // A rim seen more grazing than the pixel (unknown incidence: grazing) ends a surface that
  // turns towards the line of sight: the silhouette of a convex surface, behind which the ray
  // leaves no earlier than at the silhouette's depth, sine (1 + sine) times the plane's travel
  // (a sphere: half its chord 2 r cos against r (1 - sine) / (cos sine); issue 22). On a plane
  // the incidences of two pixels differ by at most the angle between their rays (D px apart:
  // D radians_per_px), so only a rim more grazing than that (and the estimate's noise) turns.
  const float distance_px = std::sqrt(squared_px);
  const float rim_sine = rim_c < 0.0f ? 1.0f : std::sqrt(std::max(0.0f, 1.0f - rim_c * rim_c));
  // (Only read where near_rim: and-ing it in here kept the AVX2 copy from vectorising.)
  const bool turning = rim_sine > sine + distance_px * s.radians_per_px + kSilhouetteSineMargin;
  const float factor = turning ? std::max(1.0f, sine * (1.0f + sine)) : 1.0f;
  const float travel = factor * scale * distance_px * z / std::max(c * sine, 1e-6f);
  float a = near_rim ? std::min(reach, std::max(s.voxel, travel)) : reach;
  const float fallback_squared = s.fallback_radius_px * s.fallback_radius_px;
  a = c < 0.0f ? (near_rim & (squared_px <= fallback_squared) ? s.voxel : s.truncation) : a;
  a = is_seed ? s.voxel : a;
  return valid ? a : s.truncation;
}

/// The grazing reach alone (no rims) at |cos(incidence)| `cosine`: min(reach_max, max(mu,
/// reach / cosine)); mu where the incidence is unknown (cosine <= 0) or reach is 0.
float grazingReach(float cosine, const RimAllowanceSettings& settings);

}  // namespace downstream_perception
