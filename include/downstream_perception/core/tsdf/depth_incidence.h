// The angle at which each pixel's ray meets the surface it sees, estimated from a depth image:
// the TSDF integrator's rim distance rule, grazing reach, fixed-radius relief and unconfirmed
// voxels read it.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace downstream_perception {

struct PinholeCamera;

/// Whether the inverse depth `predicted` (> 0; from the plane of neighbouring pixels) lies
/// within `tol` (m) of the depth d: |d - 1 / predicted| <= tol.
[[gnu::always_inline]] inline bool predictsDepth(float predicted, float d, float tol) {
  return (predicted > 0.0f) & (std::abs(d * predicted - 1.0f) <= tol * predicted);
}

/// |cos| of the angle between pixel (u, v)'s ray and the surface normal, estimated from the
/// neighbours (along the row and along the column) nearest in depth within `jump` (m); -1 when
/// either direction has no such neighbour (a far grazing surface stepping by more than jump per
/// pixel) or the surface is degenerate. plane_tol > 0 (m): along a row or column where the
/// pixel and both its neighbours lie on one plane (inverse depth affine: the two predict the
/// third within plane_tol), a neighbour beyond `jump` counts too (such a far grazing surface
/// gets an estimate). depth: m (NaN where not valid); inverse: 1 / depth, 0 where not a valid
/// depth.
float incidenceCosine(const PinholeCamera& camera, const float* depth, const float* inverse, int u,
                      int v, float jump, float plane_tol = 0.0f);

/// incidenceCosine (no plane tolerance) for every pixel of the image, into `cosine` (w * h): the
/// interior rows branch-free (vectorised), the border pixels one at a time. column_x: scratch,
/// reused.
void incidenceCosines(const PinholeCamera& camera, const float* depth, const float* inverse,
                      float jump, std::vector<float>* column_x, float* cosine);
/// The interior pixels of incidenceCosines (not the image's first and last rows and columns);
/// xs[u] = (u - cx) / fx.
void incidenceCosinesInterior(const PinholeCamera& camera, const float* depth, const float* inverse,
                              float jump, const float* xs, float* cosine);

/// Scratch of windowIncidenceCosines, reused from frame to frame.
struct IncidenceWindowScratch {
  /// Per pixel, 1 where it breaks a surface: not valid, or more than `jump` in depth from the
  /// next pixel along its row or its column.
  std::vector<std::uint8_t> bad;
  std::vector<float> across;  ///< per radius, inverse depth summed across the window per pixel
  /// Per radius, a row's sums down the window's rows (inverse depth, bad pixels).
  std::vector<float> down;
  std::vector<std::uint8_t> down_bad;
  std::vector<std::uint8_t> window_bad;  ///< a row's: any bad pixel in the window
  std::vector<float> slope_x, slope_y;   ///< a row's inverse-depth slopes (largest clean window)
  std::vector<std::int32_t> found;       ///< a row's: some window was clean
};

/// A noise-robust incidence for pixels inside a surface: where every neighbour pair of the
/// (2 radius + 1)^2 pixels around a pixel, and from them to the next pixel right and down,
/// continues one surface (both valid, depths within `jump`), `cosine` is overwritten with the
/// incidence of the window's mean inverse-depth slopes; failing that, the same with a window of
/// half the radius, then of radius 1; pixels with none keep their value (incidenceCosines'). On a
/// plane inverse depth is affine in the image, so the slopes are the plane's exactly, while a
/// pixel's own neighbours see depth noise of a few mm over one pixel. Windows are centred (a
/// shifted one would, near a curved surface's silhouette, report the less grazing incidence of the
/// surface inside it). radius 0: nothing changes. O(pixels x radius), in plain sums along rows
/// (vectorised; summed-area tables and running sums were slower: memory and latency bound).
void windowIncidenceCosines(const PinholeCamera& camera, const float* depth, const float* inverse,
                            float jump, int radius, IncidenceWindowScratch* scratch, float* cosine);

}  // namespace downstream_perception
